"""The benchmarks of slewing_model: ``.venv/bin/python -m benchmarks --list`` lists them (:mod:`benchmarks.suite`)."""
