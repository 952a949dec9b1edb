# Sourced by the GPU run scripts (experiments/gpu_run.sh, gpu_lip_any.sh) with LOG set: installs the wheels of WHEELS
# (a folder, for a host without grain and the like; no index, no dependencies), sets the environment of a run, and
# checks that jax, flax and grain import (exit 3 or 4 otherwise, with the reason in LOG).
if [ -n "${WHEELS:-}" ]; then
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site \
    "$WHEELS"/*.whl >> "$LOG" 2>&1 || { echo "installing $WHEELS failed" >> "$LOG"; exit 3; }
  export PYTHONPATH=/tmp/site:$PWD
fi
export PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false JAX_COMPILATION_CACHE_DIR=/tmp/jaxcache
python3 -c "import jax, flax, grain; print('jax', jax.__version__, 'flax', flax.__version__, jax.devices())" \
  >> "$LOG" 2>&1 || { echo "import failed" >> "$LOG"; exit 4; }
