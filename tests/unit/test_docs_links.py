"""Every relative link in the README and the guides leads to a file that exists, and every ``#anchor`` to a heading
that exists in it (anchors made as GitHub makes them from a heading's text)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCUMENTS = sorted([REPO / "README.md", REPO / "deploy" / "README.md", *(REPO / "docs").glob("*.md")])

_FENCE = re.compile(r"^```.*?^```", re.M | re.S)
_INLINE_CODE = re.compile(r"`[^`\n]*`")
_LINK = re.compile(r"(?<!!)\[[^\]\n]*\]\(([^)\s]+)\)")
_HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$", re.M)


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"`([^`]*)`", r"\1", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"[^\w\- ]", "", text.lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """Every anchor a markdown file offers (a repeated heading gets -1, -2, ... as on GitHub)."""
    seen: dict[str, int] = {}
    out: set[str] = set()
    for match in _HEADING.finditer(_FENCE.sub("", path.read_text(encoding="utf-8"))):
        base = slug(match.group(2))
        count = seen.get(base, 0)
        out.add(base if count == 0 else f"{base}-{count}")
        seen[base] = count + 1
    return out


def links(path: Path) -> list[str]:
    text = _INLINE_CODE.sub("", _FENCE.sub("", path.read_text(encoding="utf-8")))
    return [m.group(1) for m in _LINK.finditer(text)]


def test_the_slugs_are_githubs() -> None:
    """A few headings of the guides, with the anchors GitHub shows for them."""
    assert slug("MyRobot, notebook 15's robot") == "myrobot-notebook-15s-robot"
    assert slug("To ROS 2 (export --ros2)") == "to-ros-2-export---ros2"
    assert slug("Launch-file plumbing: namespaces, launch arguments") == "launch-file-plumbing-namespaces-launch-arguments"
    assert slug("`rrbot-workshop` commands") == "rrbot-workshop-commands"


@pytest.mark.parametrize("document", DOCUMENTS, ids=lambda p: str(p.relative_to(REPO)))
def test_every_relative_link_and_anchor_exists(document: Path) -> None:
    """A relative link names an existing file (or folder); an anchor names a heading of that file."""
    broken = []
    for target in links(document):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file_part, _, anchor = target.partition("#")
        linked = (document.parent / file_part).resolve() if file_part else document
        if not linked.exists():
            broken.append(f"{target}: no file {linked.relative_to(REPO) if REPO in linked.parents else linked}")
            continue
        if anchor and linked.suffix == ".md" and anchor not in anchors(linked):
            broken.append(f"{target}: no heading with the anchor #{anchor} in {linked.relative_to(REPO)} "
                          f"(it has: {', '.join(sorted(anchors(linked)))})")
    assert not broken, f"{document.relative_to(REPO)}: " + "; ".join(broken)


def test_the_readme_is_what_a_learner_reads_first() -> None:
    """The README stays short: what this is, the two commands, the course, how to work through it, and links."""
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 150, f"README.md has {len(lines)} lines; move detail to docs/"
    text = "\n".join(lines)
    assert "./workshop start" in text and "./workshop test" in text
