"""The error every engine raises for a run request it cannot honour, apart from the engines themselves.

It is a module of its own so that the engines import it without importing their package, whose
:func:`validate.engines.engines` imports them (the package re-exports it).
"""


class EngineInputError(ValueError):
    """A run request an engine cannot honour (e.g. an output step that is not a whole number of its
    time steps); ``option`` names the command-line option at fault (``--dt-out``, ``--duration``), and
    the command line reports it as bad input."""

    def __init__(self, option: str, message: str):
        self.option = option
        super().__init__(message)
