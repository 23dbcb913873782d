"""A deliberately blind navigation method for the benchmark's wall test
(tests/campaign/nav_e2e_test.cc): it trots straight ahead at 0.4 m/s over the ZeroMQ bridge,
ignoring the goal and every obstacle, until the run ends. A real external process, so the
harness's collision counting is exercised on real contacts.

usage: PYTHONPATH=python python3 straight_driver.py ENDPOINT
"""

import sys

from penumbra_client import Client, RunEndedError


def main():
    with Client(sys.argv[1], timeout_sec=60.0, name="straight_driver") as c:
        c.twist(vx=0.4)
        try:
            while not c.step(50).ended:
                pass
        except RunEndedError:
            return 0


if __name__ == "__main__":
    sys.exit(main())
