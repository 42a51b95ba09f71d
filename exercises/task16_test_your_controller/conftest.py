"""pytest's set-up for your tests (you need not change it): the fixture ``controller_class``.

Run by you (``pytest exercises/task16_test_your_controller``), ``controller_class`` is your DisplacementController of
task 8 (the library's reference while yours is unfinished). The grader of task 16 gives your tests other controllers in
its place: a correct one, one that does nothing, and wrong ones.
"""

from rrbot_workshop.course.controller_tests import controller_class  # noqa: F401 - a fixture pytest finds here
