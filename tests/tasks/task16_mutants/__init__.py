"""The task-16 grader's hidden wrong controllers: a student copy of the course leaves this folder out.

Each module declares wrong displacement controllers with :func:`task16_public_mutants.wrong` (one rule broken each,
written as a learner would); importing this package registers them all in ``task16_public_mutants.REGISTRY``, after
the public ones, in the order notebook 08 states the rules.
"""

import importlib

MODULES = ("parameters", "messages", "update", "lifecycle")

for _name in MODULES:
    importlib.import_module(f"task16_mutants.{_name}")
