"""A misbehaving controller process for the fault tests: ``python bad_drive.py MODE T_BAD N``.

It answers each ``lcmt_iiwa_status`` of an N-joint arm on IIWA_STATUS (default URL) with a
torque-only command, zero torques, until the status time reaches T_BAD; then by MODE:
``nan`` (a NaN torque), ``over`` (100 N·m), ``size`` (N + 1 torques), ``rogue`` (it answers
nothing before T_BAD and from then on publishes, for each status, a second command with the
status's stamp and other torques: a second sender beside the real drive).
"""

from __future__ import annotations

import sys
import time

import numpy as np

from ptint_drake.hardware.link import COMMAND_CHANNEL, STATUS_CHANNEL, Endpoint, pack_command, unpack_status


def main() -> None:
    mode, t_bad, n = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
    link = Endpoint(None, listen=STATUS_CHANNEL, publish=COMMAND_CHANNEL)
    end = time.monotonic() + 30.0
    while time.monotonic() < end:
        for _, data in link.poll(0.05):
            utime, _, _ = unpack_status(data, n)
            late = utime * 1e-6 >= t_bad
            if mode == "rogue":
                if late:
                    link.publish(pack_command(utime, np.full(n, 0.123)))
                continue
            tau = np.zeros(n)
            if late:
                tau = {
                    "nan": np.array([np.nan] + [0.0] * (n - 1)),
                    "over": np.full(n, 100.0),
                    "size": np.zeros(n + 1),
                }[mode]
            link.publish(pack_command(utime, tau))


if __name__ == "__main__":
    main()
