"""Aerodynamic models: coefficient tables (``tables``), their build-up from geometry, and the
interpolated and simplified models behind one interface (``model``)."""

from .airdata import AirData as AirData
from .airdata import air_data as air_data
from .model import AeroCoefficients as AeroCoefficients
from .model import LinearAero as LinearAero
from .model import TableAero as TableAero
from .model import aero_coefficients as aero_coefficients
from .model import aero_wrench as aero_wrench
