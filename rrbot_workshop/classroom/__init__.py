"""The classroom: the course's two commands (``./workshop start|test``), a workspace per learner on a hub, the room
and its deployment, and the instructor's class report.
"""
