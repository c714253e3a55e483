"""Atmosphere, mean wind, Dryden turbulence and the geomagnetic field."""

from .atmosphere import AtmosphereState as AtmosphereState
from .atmosphere import G0 as G0
from .atmosphere import isa as isa
from .turbulence import Turbulence as Turbulence
from .turbulence import TurbulenceState as TurbulenceState
from .turbulence import advance_turbulence as advance_turbulence
from .turbulence import gust_n as gust_n
from .turbulence import initial_turbulence as initial_turbulence
from .turbulence import turbulence_noise as turbulence_noise
from .turbulence import turbulence_scales as turbulence_scales
from .wind import PowerLawWind as PowerLawWind
from .wind import WindLayers as WindLayers
from .wind import WindProfile as WindProfile
from .magnetic import DipoleCoefficients as DipoleCoefficients
from .magnetic import dipole_field_ned as dipole_field_ned
from .magnetic import igrf_dipole as igrf_dipole
from .magnetic import site_field_ned as site_field_ned
