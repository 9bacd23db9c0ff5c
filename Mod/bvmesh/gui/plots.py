"""Pictures: the convergence plot and the distance map's legend in dialogs, and a picture of
the distance map (3D view + legend) saved as PNG."""

import os

import FreeCAD
import FreeCADGui

from bvmesh.features.distance_map import RAMP

IMAGE_DIALOG_NAME = "BVMeshImageDialog"
_open_dialogs = []


def output_dir():
    """Beside the saved document, else in FreeCAD's user data folder."""
    doc = FreeCAD.ActiveDocument
    if doc is not None and doc.FileName:
        return os.path.dirname(doc.FileName)
    folder = os.path.join(FreeCAD.getUserAppDataDir(), "BVMesh")
    os.makedirs(folder, exist_ok=True)
    return folder


def default_plot_path(fit):
    return os.path.join(output_dir(), "{}_{}_convergence.png".format(fit.Document.Name, fit.Name))


def show_image(title, path, text=None):
    """A non-modal dialog showing the PNG at `path` (and a caption)."""
    from PySide import QtCore, QtGui

    dialog = QtGui.QDialog(FreeCADGui.getMainWindow())
    dialog.setObjectName(IMAGE_DIALOG_NAME)
    dialog.setWindowTitle(title)
    dialog.setAttribute(QtCore.Qt.WA_DeleteOnClose)
    layout = QtGui.QVBoxLayout(dialog)
    label = QtGui.QLabel()
    label.setPixmap(QtGui.QPixmap(path))
    layout.addWidget(label)
    if text:
        layout.addWidget(QtGui.QLabel(text))
    layout.addWidget(QtGui.QLabel("Saved as {}".format(path)))
    buttons = QtGui.QDialogButtonBox(QtGui.QDialogButtonBox.Close)
    buttons.rejected.connect(dialog.close)
    layout.addWidget(buttons)
    _open_dialogs.append(dialog)
    dialog.destroyed.connect(lambda *args: _open_dialogs.remove(dialog) if dialog in _open_dialogs else None)
    dialog.show()
    return dialog


def _colormap():
    from matplotlib.colors import LinearSegmentedColormap

    return LinearSegmentedColormap.from_list("bvmesh_distance", [tuple(c) for c in RAMP])


def save_legend(dmap, path):
    """The distance map's colour legend (0 .. LegendMax) as a PNG."""
    return save_colorbar(path, 0.0, dmap.LegendMax, "distance", "red: {:.3g} and more".format(dmap.LegendMax))


def save_colorbar(path, low, high, title, note=""):
    """A vertical colour bar of the distance map's ramp from low to high, as a PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colorbar import ColorbarBase
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    figure = Figure(figsize=(1.8, 4.0), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_axes([0.15, 0.05, 0.25, 0.85])
    ColorbarBase(axes, cmap=_colormap(), norm=Normalize(low, high if high > low else low + 1.0),
                 orientation="vertical")
    axes.set_title(title, fontsize=9)
    axes.set_ylabel(note, fontsize=8)
    figure.savefig(path)
    return path


def show_cut_legend(cut):
    """The colour legend of a GridCut coloured by a quality metric, in a dialog."""
    path = os.path.join(output_dir(), "{}_{}_legend.png".format(cut.Document.Name, cut.Name))
    save_colorbar(path, cut.ValueMin, cut.ValueMax, cut.Metric.replace("_", " "),
                  "{:.3g} .. {:.3g}".format(cut.ValueMin, cut.ValueMax))
    return show_image("{} legend".format(cut.Label), path, "{} segments".format(cut.SegmentCount))


def show_legend(dmap):
    path = os.path.join(output_dir(), "{}_{}_legend.png".format(dmap.Document.Name, dmap.Name))
    save_legend(dmap, path)
    return show_image("Distance map legend", path, "max {:.4g}, RMS {:.4g} (model units)".format(
        dmap.MaxDistance, dmap.RmsDistance))


def save_distance_map_picture(dmap, path, width=1000, height=700):
    """The active 3D view (showing the distance map) with the legend beside it, as a PNG."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    import matplotlib.image

    view_path = path + ".view.png"
    FreeCADGui.activeDocument().activeView().saveImage(view_path, width, height, "White")
    image = matplotlib.image.imread(view_path)
    os.remove(view_path)
    figure = Figure(figsize=(width / 100.0 + 1.6, height / 100.0), dpi=100)
    FigureCanvasAgg(figure)
    axes = figure.add_axes([0.0, 0.0, width / (width + 160.0), 1.0])
    axes.imshow(image)
    axes.set_axis_off()
    legend = figure.add_axes([width / (width + 160.0) + 0.02, 0.1, 0.03, 0.8])
    mappable = ScalarMappable(norm=Normalize(0.0, dmap.LegendMax), cmap=_colormap())
    figure.colorbar(mappable, cax=legend)
    legend.set_title("distance", fontsize=9)
    legend.set_ylabel("red: {:.3g} and more".format(dmap.LegendMax), fontsize=8)
    figure.text(0.01, 0.97, "{}: max {:.4g}, RMS {:.4g}".format(dmap.Label, dmap.MaxDistance, dmap.RmsDistance),
                fontsize=10, va="top")
    figure.savefig(path)
    return path
