"""`python -m prebo`: the command line (prebo.cli.main)."""
import sys

from .cli import main

sys.exit(main())
