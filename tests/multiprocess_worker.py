"""One process of the 2-process training test (tests/test_train.py): run as
    python tests/multiprocess_worker.py PROCESS_ID PORT WORKDIR OUT.npz
It trains the first MULTI_PROCESS_STEPS steps of the test CONFIG with jax.distributed over CPU (gloo collectives)
and, in process 0, saves G."""
import sys

import jax

jax.config.update("jax_cpu_collectives_implementation", "gloo")


def main(process_id: int, port: int, workdir: str, out: str) -> None:
    jax.distributed.initialize(coordinator_address=f"127.0.0.1:{port}", num_processes=2, process_id=process_id)
    import numpy as np

    sys.path.insert(0, __file__.rsplit("/", 1)[0])
    from test_train import CONFIG, MULTI_PROCESS_STEPS

    from lipjax.train.checkpoint import to_host
    from lipjax.train import loop

    assert jax.process_count() == 2 and len(jax.devices()) == 2
    state = loop.train(CONFIG, workdir, stop_at=MULTI_PROCESS_STEPS, progress=False)
    if process_id == 0:
        leaves = jax.tree_util.tree_leaves(state.g_params)
        np.savez(out, *[to_host(a) for a in leaves])
    jax.distributed.shutdown()


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4])
