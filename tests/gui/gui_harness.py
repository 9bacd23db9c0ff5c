"""What every GUI test macro shares: output to the terminal (print goes to FreeCAD's Report view),
checks that stop the test, waiting in the event loop, and the start that ends FreeCAD with the
test's exit code (an uncaught exception would leave the GUI open)."""

import os
import sys
import time
import traceback

from PySide import QtCore, QtGui


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


def when_shown(find, act, timeout_ms=60000):
    """Polls (in the event loop) until find() returns a widget, then calls act(widget) once. Past
    the deadline it stops, and a modal dialog still open then (one the test did not expect, which
    would block the test for good) is named and rejected, so the test goes on to fail instead of
    hanging."""
    deadline = time.time() + timeout_ms / 1000.0
    timer = QtCore.QTimer()

    def poll():
        widget = find()
        if widget is not None:
            timer.stop()
            act(widget)
        elif time.time() > deadline:
            timer.stop()
            modal = QtGui.QApplication.activeModalWidget()
            if modal is not None:
                print("the awaited widget did not appear within {:.0f} s; rejecting the modal {} '{}'".format(
                    timeout_ms / 1000.0, type(modal).__name__, modal.windowTitle()), flush=True)
                modal.reject()

    timer.timeout.connect(poll)
    timer.start(20)
    return timer


def main_window():
    import FreeCADGui

    return FreeCADGui.getMainWindow()


def toolbar_action(name):
    for bar in main_window().findChildren(QtGui.QToolBar):
        for action in bar.actions():
            if action.objectName() == name:
                return action
    raise AssertionError("no toolbar button for " + name)


def click_toolbar(name):
    action = toolbar_action(name)
    deadline = time.time() + 5.0
    while not action.isEnabled() and time.time() < deadline:  # FreeCAD updates buttons on a timer
        settle(50)
    check(action.isEnabled(), "the {} button is enabled".format(name))
    action.trigger()
    settle()


def press_task_ok():
    """Presses OK of the task dialog shown in the combo view."""
    for box in main_window().findChildren(QtGui.QDialogButtonBox):
        ok = box.button(QtGui.QDialogButtonBox.Ok)
        if box.isVisible() and ok is not None and ok.isVisible():
            ok.click()
            settle()
            return
    raise AssertionError("no task dialog with an OK button is shown")


def start_macro_recording(folder, name):
    """Starts FreeCAD's macro recorder on folder/name.FCMacro (replacing an old one)."""
    import FreeCADGui

    macro = os.path.join(folder, name + ".FCMacro")
    if os.path.exists(macro):
        os.remove(macro)

    def fill(dialog):
        dialog.findChild(QtGui.QLineEdit, "lineEditPath").setText(name)
        dialog.findChild(QtGui.QLineEdit, "lineEditMacroPath").setText(folder + os.sep)
        dialog.findChild(QtGui.QPushButton, "buttonStart").click()

    timer = when_shown(lambda: QtGui.QApplication.activeModalWidget(), fill)
    FreeCADGui.runCommand("Std_DlgMacroRecord")  # modal: returns when Record was pressed
    timer.stop()


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
