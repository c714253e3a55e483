"""Aerodynamic models."""

from .airdata import AirData as AirData
from .airdata import air_data as air_data
from .linear import LinearAero as LinearAero
from .linear import linear_aero_wrench as linear_aero_wrench
