"""What a player sees and hears: the game renderer, the game window and the demo windows.

The only package that imports pygame. Nothing below it (physics, game, records, demos' pure
runs) imports it, so headless runs never start SDL's display or mixer.
"""
