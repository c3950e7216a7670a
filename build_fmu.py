"""Build dist/Pendulum.fmu from fmu_src/ and modelDescription.xml: `pendulum-fmu build` from a
checkout, for every platform whose compiler is installed (see --help).
"""

import sys

from pendulum_fmu.cli import main

if __name__ == "__main__":
    sys.exit(main(["build", *sys.argv[1:]]))
