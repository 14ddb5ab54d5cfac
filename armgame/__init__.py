"""armgame: drive a simulated two-joint arm with four muscle keys to hit targets."""

import os

# pygame prints a banner on import; a command-line tool's output should be its own.
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

__version__ = "0.5.0"
