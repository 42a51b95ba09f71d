"""``python -m rrbot_workshop start|test``: the course's two commands (see :mod:`rrbot_workshop.classroom.launcher`).

``--help`` / ``-h`` print the usage and exit 0, as command-line tools do; anything else goes to the launcher.
"""

import sys

from rrbot_workshop.classroom.launcher import USAGE, main

if sys.argv[1:2] in (["--help"], ["-h"]):
    print(USAGE)
    sys.exit(0)
sys.exit(main())
