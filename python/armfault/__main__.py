"""`python3 -m armfault ARGS`: the armfault command line (the same commands, options, outputs and
exit statuses as the `armfault` binary), run in this Python process so that a campaign whose
monitor is a Python class named by import path, {"type": "python", "class":
"package.module:Class"}, runs with `run`, `trace --run`, `boundary`, `report --run`, `replay` and
`validate --load-plugins` as any other monitor does (docs/monitor-api.md, "A monitor in Python").
The class's module is imported as Python imports it: from sys.path (the current directory, then
PYTHONPATH)."""

import sys

from . import _armfault


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    sys.stdout.flush()
    sys.stderr.flush()
    return _armfault.cli_main(["armfault"] + argv)


if __name__ == "__main__":
    sys.exit(main())
