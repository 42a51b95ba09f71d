"""``python -m rrbot_workshop start|test``: the course's two commands (see :mod:`rrbot_workshop.course.launcher`)."""

import sys

from rrbot_workshop.course.launcher import main

sys.exit(main())
