"""Vectors and quaternions, table interpolation and fixed-step integrators."""

from .integrators import rk4_step as rk4_step
from .interp import interp1d as interp1d
from .safe import safe_arctan2 as safe_arctan2
from .safe import safe_sqrt as safe_sqrt
from .vectors import Quat as Quat
from .vectors import Vec3 as Vec3
