"""The game: muscles, rules and the fixed-step session. Pure Python; nothing here draws."""
