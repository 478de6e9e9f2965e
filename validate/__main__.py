"""Entry point of ``python -m validate``."""

import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while importing: the same one line as during a command
    print("error: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
