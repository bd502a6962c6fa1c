import sys

from recipdyn.cli import main

sys.exit(main())
