"""Test-session setup: faster XLA compiles (tests are compile-bound, not run-bound), one persistent cache for the
session and for every `lipjax` command the tests run (in-process or as a subprocess), and a deterministic
Hypothesis profile."""
import os
import pathlib

# Must be set before jax is imported anywhere. Halves compile time of the small networks in these tests.
os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") + " --xla_backend_optimization_level=0").strip()
# main() of the CLI and the experiments enables the cache from $LIPJAX_CACHE_DIR: the same folder as the session's.
os.environ["LIPJAX_CACHE_DIR"] = str(pathlib.Path(__file__).resolve().parents[1] / ".jax_cache")

import lipjax  # noqa: E402
from hypothesis import settings  # noqa: E402

lipjax.enable_compilation_cache()

# The same Hypothesis examples on every run and machine; failures are not replayed from a local database.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.load_profile("deterministic")
