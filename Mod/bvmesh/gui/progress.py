"""Progress and cancel for long fits: the fitter runs in a worker thread (the core releases the
GIL) while the GUI thread shows each pass in a modal progress dialog and the status bar, so the
window stays responsive and Cancel is honoured after the current step."""

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
        status.showMessage("BVMesh fit: {}".format(outcome["summary"]["reason"]), 10000)
        return outcome["summary"]
