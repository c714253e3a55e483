"""Sensors with realistic errors, ready-made parts and the avionics bus (docs/sensors.md)."""
