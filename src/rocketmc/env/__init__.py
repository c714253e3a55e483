"""Atmosphere and wind."""

from .atmosphere import AtmosphereState as AtmosphereState
from .atmosphere import G0 as G0
from .atmosphere import isa as isa
from .wind import WindLayers as WindLayers
from .wind import layered_wind as layered_wind
