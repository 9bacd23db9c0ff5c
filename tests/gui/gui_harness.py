"""What every GUI test macro shares: output to the terminal (print goes to FreeCAD's Report view),
checks that stop the test, waiting in the event loop, and the start that ends FreeCAD with the
test's exit code (an uncaught exception would leave the GUI open)."""

import os
import sys
import traceback

from PySide import QtCore


def log(message):
    sys.__stdout__.write(message + "\n")
    sys.__stdout__.flush()


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    log("ok: " + message)


def settle(milliseconds=300):
    """Runs the event loop for a while, so the GUI catches up."""
    loop = QtCore.QEventLoop()
    QtCore.QTimer.singleShot(milliseconds, loop.quit)
    loop.exec_()


def start(run):
    """Calls run() once the main window shows, then exits FreeCAD: 0 if run() returned, 1 if it raised."""
    def main():
        code = 1
        try:
            run()
            code = 0
        except Exception:
            log(traceback.format_exc())
        finally:
            os._exit(code)

    QtCore.QTimer.singleShot(500, main)
