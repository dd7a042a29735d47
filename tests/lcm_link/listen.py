"""A bystander on the LCM group (inside the private namespace, beside ``ptint hardware`` and
``ptint drive``): every channel that crosses the wire, whoever publishes it, with the count of
its messages — ``python listen.py SECONDS [QUIET_S]``.  It stops SECONDS after its start, or
QUIET_S (default 3) after the last message once one came, and prints {channel: count} as JSON.
"""

from __future__ import annotations

import json
import sys
import time

from pydrake.lcm import DrakeLcm


def main() -> None:
    limit = float(sys.argv[1])
    quiet = float(sys.argv[2]) if len(sys.argv) > 2 else 3.0
    lcm = DrakeLcm()  # the default URL, as the two commands use it
    seen: dict[str, int] = {}
    last = [None]

    def note(channel: str, _data: bytes) -> None:
        seen[channel] = seen.get(channel, 0) + 1
        last[0] = time.monotonic()

    lcm.SubscribeAllChannels(note)
    start = time.monotonic()
    while time.monotonic() - start < limit:
        lcm.HandleSubscriptions(50)
        if last[0] is not None and time.monotonic() - last[0] > quiet:
            break
    print(json.dumps(seen))


if __name__ == "__main__":
    main()
