"""``python -m softbench.cli``: the command line without the launcher's backend check."""

import sys

from softbench.cli import main

sys.exit(main())
