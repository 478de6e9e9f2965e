"""Entry point of ``python -m validate``.

One BLAS thread unless the user chose otherwise, set before numpy loads OpenBLAS: the tool's linear algebra
is thousands of small solves (a few thousand rows, a few columns), which OpenBLAS's threads slow down, and
``validate all`` already runs two workers on two cores; under load the threads' waiting took a ``validate
all`` from 44 s to 75 s where one thread took 43-48 s (``python benchmarks/blas_threads.py``).
"""

import os
import sys

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while importing: the same one line as during a command
    print("error: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
