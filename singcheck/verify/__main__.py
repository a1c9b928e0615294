"""``python -m singcheck.verify CERT...``: see :mod:`singcheck.verify`."""

import sys

from singcheck.verify import main

sys.exit(main())
