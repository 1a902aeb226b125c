"""``python -m benchmarks [NAME ...] [options]``: :func:`benchmarks.suite.main`."""
import sys

from benchmarks.suite import main

if __name__ == "__main__":      # (a process spawned by one of the benchmarks imports this module again)
    sys.exit(main())
