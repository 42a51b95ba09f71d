"""CPU-seconds of a notebook kernel: started as a new process, or forked from the server's template.

Run: ``.venv/bin/python benchmarks/bench_kernel_start.py [--runs 3] [--notebook notebooks/02_mock_hardware.ipynb]``.
Each run starts a kernel as a Jupyter server does (jupyter_client, the chosen provisioner), in the notebook's folder
on the exercises track, and runs every code cell of the notebook through the kernel protocol. Printed per way: the
kernel process's CPU time (user + system, its own and its finished children's, from /proc) when it is ready and after
the last cell; the template's own start is printed once, apart (on a hub it is spent before the learners arrive).
The notebook's self-checks grade in a child of the kernel's copy, which is not in these figures (see bench_room.py for
everything a learner costs). Linux only; nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from rrbot_workshop.classroom import kernels

ROOT = Path(__file__).resolve().parent.parent


def _cpu(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return sum(int(f) for f in fields[11:15]) / os.sysconf("SC_CLK_TCK")


def _run(provisioner: str, notebook: Path) -> tuple[float, float]:
    from jupyter_client import KernelManager
    from jupyter_client.provisioning import KernelProvisionerFactory

    cells = [c["source"] if isinstance(c["source"], str) else "".join(c["source"])
             for c in json.loads(notebook.read_text())["cells"] if c["cell_type"] == "code"]
    KernelProvisionerFactory.instance().default_provisioner_name = provisioner
    manager = KernelManager(kernel_name="python3")
    manager.start_kernel(cwd=str(notebook.parent), env={**os.environ, "RRBOT_WORKSHOP_TRACK": "exercises"})
    client = manager.client()
    client.start_channels()
    try:
        client.wait_for_ready(timeout=120)
        pid = manager.provisioner.process.pid
        ready = _cpu(pid)
        for cell in cells:
            reply = client.execute_interactive(cell, timeout=300, output_hook=lambda message: None)
            if reply["content"]["status"] != "ok":
                raise SystemExit(f"a cell failed ({reply['content'].get('ename')}):\n{cell[:200]}")
        return ready, _cpu(pid)
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="kernels per way")
    parser.add_argument("--notebook", type=Path, default=ROOT / "notebooks" / "02_mock_hardware.ipynb")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be at least 1")
    handle = kernels.template()
    started = time.perf_counter()
    if not handle.start(["-Xfrozen_modules=off"]):
        raise SystemExit("kernels are not forked on this system")
    while not handle.ready():
        time.sleep(0.05)
    process = handle._process
    print(f"template: ready after {time.perf_counter() - started:.1f} s, {_cpu(process.pid):.2f} CPU-s"
          if process else "template: not running")
    print(f"{'kernel':<24} {'CPU-s at ready (median)':>24} {'CPU-s after the cells (median / max)':>38}")
    try:
        for name, provisioner in (("new process", "local-provisioner"), ("forked from the template",
                                                                        kernels.PROVISIONER_NAME)):
            runs = [_run(provisioner, args.notebook.resolve()) for _ in range(args.runs)]
            ready = statistics.median(r[0] for r in runs)
            after = [r[1] for r in runs]
            print(f"{name:<24} {ready:>24.2f} {statistics.median(after):>31.2f} / {max(after):.2f}")
    finally:
        handle.stop()


if __name__ == "__main__":
    main()
