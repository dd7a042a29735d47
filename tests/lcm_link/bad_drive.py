"""A misbehaving controller process for the fault tests: ``python bad_drive.py MODE T_BAD N``.

It answers each ``lcmt_iiwa_status`` of an N-joint arm on IIWA_STATUS (default URL) with a
torque-only command, zero torques, until the status time reaches T_BAD; then by MODE:
``nan`` (a NaN torque), ``over`` (100 N·m), ``size`` (N + 1 torques), ``rogue`` (it answers
nothing before T_BAD and from then on publishes, for each status, a second command with the
status's stamp and other torques: a second sender beside the real drive; it prints the stamp of
its first command, ``first UTIME``).  It ends 2 s after the last status.
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
    first = None
    last = None
    while time.monotonic() < end and (last is None or time.monotonic() - last < 2.0):
        messages = link.poll(0.05)
        last = time.monotonic() if messages else last
        for _, data in messages:
            utime, _, _ = unpack_status(data, n)
            late = utime * 1e-6 >= t_bad
            if mode == "rogue":
                if late:
                    if first is None:
                        first = utime
                        print(f"first {utime}", flush=True)  # the stamp of its first command
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
