"""Test-session setup: faster XLA compiles (tests are compile-bound, not run-bound) and a persistent cache."""
import os
import pathlib

# Must be set before jax is imported anywhere. Halves compile time of the small networks in these tests.
os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " --xla_backend_optimization_level=0").strip()

import lipjax  # noqa: E402

lipjax.enable_compilation_cache(pathlib.Path(__file__).resolve().parents[1] / ".jax_cache")
