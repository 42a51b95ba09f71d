"""The course around the library: tracks (exercises or solutions), grading, the notebook magics, the CLI."""
