"""``rrbot-workshop lint``: a controllers YAML and a description, checked as ROS 2 Jazzy would load them.

:mod:`~rrbot_workshop.tools.lint.linter` runs the checks; :mod:`~rrbot_workshop.tools.lint.layout` reads the YAML's
node layout, :mod:`~rrbot_workshop.tools.lint.parameters` checks parameters, :mod:`~rrbot_workshop.tools.lint.classes`
configures controller classes for their interfaces, :mod:`~rrbot_workshop.tools.lint.urdf` checks descriptions and
:mod:`~rrbot_workshop.tools.lint.descriptions` says which description each controller manager is checked against.
"""

from rrbot_workshop.tools.lint.linter import (
    Finding,
    external_plugin,
    format_findings,
    lint_controllers,
    lint_description,
)

__all__ = ["Finding", "external_plugin", "format_findings", "lint_controllers", "lint_description"]
