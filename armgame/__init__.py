"""armgame: drive a simulated two-joint arm with four muscle keys to hit targets."""

__version__ = "0.1.0"
