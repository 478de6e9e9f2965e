"""Timing helper shared by the benchmark scripts (run them from the repository root)."""

import time


def best_of(fn, repeat: int = 3) -> float:
    """Shortest wall time (s) of ``repeat`` calls: the least disturbed by other load on the machine."""
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)
