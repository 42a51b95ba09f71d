#!/usr/bin/env python3
"""rrbot_workshop's two commands, on Linux, macOS and Windows, with any Python 3.11-3.13:

    python workshop.py start   set up (the first time) and open the course in JupyterLab on 127.0.0.1
    python workshop.py test    set up (the first time) and run every test: library, graders, notebooks

(On Windows: ``py workshop.py start``.) Only the standard library is used until the course is installed.
"""

import importlib.util
import sys
from pathlib import Path

_HERE = Path(__file__).resolve().parent
_spec = importlib.util.spec_from_file_location("rrbot_workshop_launcher", _HERE / "rrbot_workshop" / "classroom" / "launcher.py")
assert _spec is not None and _spec.loader is not None
_launcher = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_launcher)

if __name__ == "__main__":
    sys.exit(_launcher.main(sys.argv[1:], root=_HERE))
