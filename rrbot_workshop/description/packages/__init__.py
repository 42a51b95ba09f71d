"""Packages found as ROS finds them: a package path, ``package.xml`` names, source and installed trees.

ROS finds a package by the ``<name>`` in its ``package.xml``, below the folders of a package path
(``ROS_PACKAGE_PATH`` in ROS 1; a colcon workspace's ``src/`` or an install prefix in ROS 2). This module does the
same without ROS. The package path is, in order:

1. the folders given by the caller (``rw.bringup(..., package_path=[...])``, ``--package-path DIR``);
2. the folders of ``RRBOT_WORKSHOP_PACKAGE_PATH`` (``os.pathsep``-separated, as ``ROS_PACKAGE_PATH``);
3. the course's ``descriptions/`` folder (:func:`~rrbot_workshop.description.xacro.descriptions_root`), whose
   sub-folders are packages named after the folder when they have no ``package.xml``.

Each folder is crawled as colcon crawls a workspace: a folder with a ``package.xml`` is a package and is not
descended into; folders holding ``COLCON_IGNORE``, ``AMENT_IGNORE`` or ``CATKIN_IGNORE`` and hidden folders are
skipped. An install prefix (``<prefix>/share/<pkg>/package.xml``) may be given directly; its ``share/*`` packages
are taken without crawling the rest of the prefix. When two packages have the same name, the first on the path
wins, as in ROS, and a warning names both.

**Source trees resolve as their installed form would.** ``$(find pkg)`` in ROS 2 is the package's *installed*
``share/<pkg>`` folder, and CMake's ``install(DIRECTORY ... DESTINATION share/${PROJECT_NAME})`` rules decide
what is there: ``install(DIRECTORY description/ros2_control DESTINATION share/${PROJECT_NAME})`` puts
``description/ros2_control/x.xacro`` at ``share/<pkg>/ros2_control/x.xacro``. For a package found as a source
tree, :meth:`Package.candidates` reads those rules from its ``CMakeLists.txt`` (``DIRECTORY`` with CMake's
trailing-slash meaning, ``FILES`` with ``RENAME``, ``${PROJECT_NAME}`` and simple ``set()`` variables) and maps a
share-relative path back to the source file. A package without such rules (``ament_python``, or rules this
reader cannot follow) resolves relative to its source folder.

**How ``$(find pkg)`` works in xacro.** Xacro pastes the result of ``$(find pkg)`` into text
(``$(find pkg)/ros2_control/x.xacro``) and opens the file later, so it needs a real folder that looks like the
installed one. For a source tree with install rules, :func:`share_directory` writes that folder, the *install view*:
:func:`~rrbot_workshop.description.packages.installed.install_tree` replays the rules in memory, in CMake's order
(a later rule overwrites an earlier file; ``RENAME``; a folder or only its contents), and
:mod:`~rrbot_workshop.description.packages.view` writes the result under this process's own folder
(``<tmp>/rrbot_workshop_views-<uid>/<pid>-<random>/<n>/share/<pkg>``) as real folders and links to the source
files. It writes nowhere else: never through a link, never outside that folder. The folder is removed when the
process exits, and one left by a killed process is removed by the next. Relative includes then behave as in the
installed package, and a file missing from it is reported by :func:`explain_missing` with every place it was looked
for. Installed trees, packages without rules and the course's ``descriptions/`` need no view: their own folder is
the share folder.

**Hostile input.** A ``DESTINATION`` that leaves the install prefix (``../x``) is refused with the file, line and
rule; ``CMakeLists.txt`` is read in time linear in its size (:mod:`~rrbot_workshop.description.packages.cmake`);
the crawl and the installed tree follow links with loop detection, never walk out of the folders they were given,
and stop at a bounded number of folders and files.
"""

from rrbot_workshop.description.packages.cmake import parse_cmake
from rrbot_workshop.description.packages.crawl import (
    DESCRIPTIONS_ENV,
    IGNORE_MARKERS,
    PACKAGE_PATH_ENV,
    Package,
    PackageIndex,
    clear_cache,
    descriptions_root,
    find_package,
    known_package,
    package_index,
    package_path,
    use_package_path,
)
from rrbot_workshop.description.packages.install_rules import InstallRule, parse_install_rules
from rrbot_workshop.description.packages.installed import InstallTree, install_tree
from rrbot_workshop.description.packages.resolve import (
    explain_missing,
    package_of,
    resolve,
    resolve_uri,
    share_directory,
    split_package_reference,
    view_to_source,
)
from rrbot_workshop.description.packages.view import remove_stale_views, views_parent

__all__ = [
    "PACKAGE_PATH_ENV",
    "DESCRIPTIONS_ENV",
    "IGNORE_MARKERS",
    "InstallRule",
    "parse_install_rules",
    "parse_cmake",
    "InstallTree",
    "install_tree",
    "remove_stale_views",
    "views_parent",
    "Package",
    "PackageIndex",
    "descriptions_root",
    "package_path",
    "package_index",
    "find_package",
    "known_package",
    "resolve",
    "resolve_uri",
    "split_package_reference",
    "share_directory",
    "explain_missing",
    "view_to_source",
    "package_of",
    "use_package_path",
    "clear_cache",
]
