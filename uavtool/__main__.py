"""``python -m uavtool`` runs the command line."""

from uavtool.cli import main

main()
