"""The ``glint`` command: the same program as the Rust build's ``glint``,
run in this process (``pip install`` puts it on PATH)."""

from __future__ import annotations

import os
import signal
import sys

from . import _glint


def main() -> None:
    # Glint handles Ctrl-C and SIGTERM itself (an interrupted render writes
    # the pixels it finished and exits 130 or 143); Python's handler would
    # raise KeyboardInterrupt over that.
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    program = os.path.abspath(sys.argv[0])
    sys.exit(_glint.main(program, ["glint", *sys.argv[1:]]))


if __name__ == "__main__":
    main()
