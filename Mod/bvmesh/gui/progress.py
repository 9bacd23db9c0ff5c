"""Progress and cancel for long fits: the fitter runs in a worker thread (the core releases the
GIL) while the GUI thread shows each pass in a modal progress dialog and the status bar, so the
window stays responsive and Cancel is honoured after the current step."""

import contextlib
import queue
import threading

import FreeCADGui

DIALOG_NAME = "BVMeshFitProgress"


def describe(record):
    return "level {level}, pass {correction}: {control_points} control points, max {max_distance:.4g}, " \
           "RMS {rms_distance:.4g}".format(**record)


class GuiFitRunner:
    """A fit runner (see bvmesh.features.surface_fit.fit_runner) with a progress dialog."""

    poll_seconds = 0.05

    def __call__(self, fitter):
        from PySide import QtCore, QtGui

        records = queue.Queue()
        stop = threading.Event()
        outcome = {}

        def work():
            try:
                outcome["summary"] = fitter.run(progress=records.put, cancel=stop)
            except BaseException as error:  # re-raised in the GUI thread
                outcome["error"] = error

        main_window = FreeCADGui.getMainWindow()
        dialog = QtGui.QProgressDialog("Starting the fit ...", "Cancel", 0, max(1, int(fitter.options["max_level"])),
                                       main_window)
        dialog.setObjectName(DIALOG_NAME)
        dialog.setWindowTitle("BVMesh: fit to tolerance")
        dialog.setWindowModality(QtCore.Qt.ApplicationModal)
        dialog.setAutoReset(False)
        dialog.setAutoClose(False)
        dialog.setMinimumDuration(0)
        dialog.setMinimumWidth(480)
        dialog.canceled.connect(stop.set)
        dialog.show()
        status = main_window.statusBar()
        worker = threading.Thread(target=work, name="BVMesh fit", daemon=True)
        worker.start()
        try:
            while worker.is_alive():
                QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
                while not records.empty():
                    record = records.get()
                    text = describe(record)
                    dialog.setLabelText(text + ("\ncancelling after this step ..." if stop.is_set() else ""))
                    dialog.setValue(min(record["level"], dialog.maximum()))
                    status.showMessage("BVMesh fit: " + text)
                worker.join(self.poll_seconds)
        finally:
            dialog.close()
            dialog.deleteLater()
        if "error" in outcome:
            raise outcome["error"]
        summary = outcome["summary"]
        status.showMessage("BVMesh fit: {}{}".format(summary["reason"],
                                                     " " + summary["detail"] if summary.get("detail") else ""), 10000)
        return outcome["summary"]


WORK_DIALOG_NAME = "BVMeshWorkProgress"


class GuiWorkRunner:
    """A work runner (bvmesh.features.common.work_runner): the work runs in a worker thread (the
    core releases the GIL) behind a modal busy dialog. Cancel gives up at once: the recompute fails
    with WorkCancelled, the transaction is aborted, and the worker's result, when it comes, is
    dropped (the core's marching and refinement cannot be stopped half-way)."""

    poll_seconds = 0.05

    def __init__(self, title):
        self.title = title

    def __call__(self, description, work):
        from PySide import QtCore, QtGui

        from bvmesh.features.common import WorkCancelled

        outcome = {}
        cancelled = threading.Event()

        def run():
            try:
                outcome["result"] = work()
            except BaseException as error:  # re-raised in the GUI thread
                outcome["error"] = error

        main_window = FreeCADGui.getMainWindow()
        dialog = QtGui.QProgressDialog(description + " ...", "Cancel", 0, 0, main_window)
        dialog.setObjectName(WORK_DIALOG_NAME)
        dialog.setWindowTitle("BVMesh: " + self.title)
        dialog.setWindowModality(QtCore.Qt.ApplicationModal)
        dialog.setMinimumDuration(0)
        dialog.setMinimumWidth(420)
        dialog.canceled.connect(cancelled.set)
        dialog.show()
        main_window.statusBar().showMessage("BVMesh: " + description)
        worker = threading.Thread(target=run, name="BVMesh " + self.title, daemon=True)
        worker.start()
        try:
            while worker.is_alive() and not cancelled.is_set():
                QtGui.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)
                worker.join(self.poll_seconds)
        finally:
            dialog.close()
            dialog.deleteLater()
        if cancelled.is_set() and worker.is_alive():
            raise WorkCancelled("{} was cancelled".format(self.title))
        if "error" in outcome:
            raise outcome["error"]
        main_window.statusBar().showMessage("BVMesh: {} done".format(self.title), 5000)
        return outcome["result"]


@contextlib.contextmanager
def work_runner_in_gui(title):
    """Runs the volume stage's long computations of the block in a worker thread with progress."""
    from bvmesh.features.common import work_runner

    with work_runner(GuiWorkRunner(title)):
        yield
