"""``python -m sensor_fit``: the ``fit_sensor`` command (:mod:`sensor_fit.cli`)."""

import sys

from sensor_fit.cli import main

if __name__ == "__main__":
    sys.exit(main())
