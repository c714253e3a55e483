"""Rigid-body dynamics, propulsion and recovery."""

from .parachute import Parachute as Parachute
from .parachute import open_fraction as open_fraction
from .parachute import parachute_drag_n as parachute_drag_n
from .propulsion import Motor as Motor
from .propulsion import propellant_mass as propellant_mass
from .propulsion import read_thrust_curve as read_thrust_curve
from .propulsion import thrust as thrust
from .rigid_body import MassProperties as MassProperties
from .rigid_body import RigidBodyState as RigidBodyState
from .rigid_body import rigid_body_derivatives as rigid_body_derivatives
