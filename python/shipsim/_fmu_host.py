"""The process that hosts one isolated FMU instance for the master (as ``shipsim fmu-host``):
``python -m shipsim._fmu_host fmu-host FMU``. The master starts it; it is not for users.

The FMI calls arrive on stdin and the replies leave on stdout (``shipsim::isolate::host``); the
process ends with the host's status, without Python's shutdown (the FMU may have left threads
or handlers behind).
"""
import os
import sys

from shipsim import _native

if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] != "fmu-host":
        sys.stderr.write("usage: python -m shipsim._fmu_host fmu-host FMU\n")
        os._exit(2)
    os._exit(_native.fmu_host(sys.argv[2]))
