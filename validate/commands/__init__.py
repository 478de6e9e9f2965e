"""Subcommands of ``python -m validate`` that have a module of their own."""
