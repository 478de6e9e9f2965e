"""Identification: moments of inertia from measured periods, signals or tensions, with their
propagated uncertainty."""
