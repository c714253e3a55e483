"""Guidance, navigation and control. So far: the canard mixing between fin deflections and the
virtual (yaw, pitch, roll, squeeze) commands of the aerodynamic model."""

from .allocation import allocate as allocate
from .allocation import mix as mix
