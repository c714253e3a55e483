"""Guidance, navigation and control (the closed loop, to come). The canard mixing between fin
deflections and the virtual (yaw, pitch, roll, squeeze) commands is the airframe's: ``aero.canards``."""
