"""Missions written on the public API alone (:mod:`uavtool.api`), as a user would write
theirs: each is registered (``uavtool fly --mission survey``, ``--mission orbit``) and is a
starting point to copy."""
