"""Placeholder: xacro processing is being written."""
from pathlib import Path


def descriptions_root() -> Path:
    raise NotImplementedError


def process_xacro(path, **mappings) -> str:
    raise NotImplementedError
