"""The other seeds' pendula: the double-arm pendulum (seed 001) and the three-body pendulum by the
TMT method (seed 002)."""
