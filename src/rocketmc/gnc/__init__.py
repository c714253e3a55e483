"""Guidance, navigation and control: the parabolic reference and the body-rate command (``guidance``), the
LQI design on the host (``design``) and its online law with the servo command (``control``); navigation is
the true state for now (``control.truth``). The canard mixing between fin deflections and the virtual
(yaw, pitch, roll, squeeze) commands is the airframe's: ``aero.canards``."""
