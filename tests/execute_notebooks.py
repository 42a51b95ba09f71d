"""Re-execute course notebooks as nbval will compare them: ``.venv/bin/python tests/execute_notebooks.py 06 08``.

Each notebook named by its number (or file name) is run top to bottom on the untouched exercises track, from the
``notebooks/`` folder, with the exercises as committed at ``HEAD`` (as ``./workshop test`` does), and saved in place.
Cells tagged ``outcome`` (what a prediction asks) keep no output. Run it after a change that alters what a notebook
shows, then look at the diff of the notebook's outputs before committing it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "rrbot_workshop" / "classroom"))
from launcher import EXERCISES_ENV, pristine_exercises  # noqa: E402  (standard library only)


def notebook_paths(names: list[str]) -> list[Path]:
    found = []
    for name in names:
        matches = sorted((ROOT / "notebooks").glob(f"{name}*.ipynb" if name[:2].isdigit() else name))
        if len(matches) != 1:
            raise SystemExit(f"'{name}' names {len(matches)} notebooks; give its number (06) or file name")
        found.append(matches[0])
    return found


def clear_outcome_cells(path: Path) -> None:
    import nbformat

    notebook = nbformat.read(path, as_version=4)
    for cell in notebook.cells:
        if cell.cell_type == "code" and "outcome" in cell.metadata.get("tags", []):
            cell.outputs, cell.execution_count = [], None
    nbformat.write(notebook, path)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="+", help="numbers (06) or file names")
    args = parser.parse_args()
    env = {**os.environ, "RRBOT_WORKSHOP_TRACK": "exercises"}
    with pristine_exercises(ROOT) as exercises:
        if exercises is not None:
            env[EXERCISES_ENV] = str(exercises)
        for path in notebook_paths(args.notebooks):
            print(f"executing {path.name}", flush=True)
            subprocess.run([sys.executable, "-m", "jupyter", "nbconvert", "--to", "notebook", "--execute", "--inplace",
                            "--ExecutePreprocessor.timeout=600", path.name], cwd=path.parent, env=env, check=True)
            clear_outcome_cells(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
