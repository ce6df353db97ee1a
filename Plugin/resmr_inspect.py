"""Inspecting cells of a .resmr file shown as Multiresolution Surface, from pvpython.

    from paraview.simple import *
    LoadPlugin("ReservoirMultiresolution.so", ns=globals())   # the plugin carries this module
    import resmr_inspect
    view = GetActiveViewOrCreate("RenderView")
    cell = resmr_inspect.PickCell(640, 360)      # display pixel, from the view's lower left
    print(cell["I"], cell["J"], cell["K"], cell["values"]["PORO"])
    resmr_inspect.GoToCell(120, 80, 12)          # camera to the cell, outlined and selected

Every call works the same in builtin and client/server (pvserver) sessions: the pick is made
where the surface renders and its result pulled from there. A pick names the cell whose colour
shows at the pixel, at whatever level of detail the view drew. Cells are ECLIPSE's I, J, K,
counted from 1."""
from paraview import simple

_OUTLINE_PATH = (0, 1, 3, 2, 0, 4, 5, 7, 6, 4, 5, 1, 3, 7, 6, 2)  # every edge of a hexahedron


def _surface(view, display):
    view = view or simple.GetActiveView()
    if display is None:
        for source in simple.GetSources().values():
            shown = simple.GetDisplayProperties(source, view)
            if shown is not None and shown.GetXMLName() == "ResMRRepresentation" and shown.Visibility:
                display = shown
                break
    if display is None:
        raise RuntimeError("no .resmr file is shown as Multiresolution Surface in the view")
    return view, display


def _result(display):
    display.UpdatePropertyInformation()
    values = {}
    for line in display.GetPropertyValue("PickedValues").splitlines():
        name, value = line.split("=", 1)
        if name == "error":
            raise RuntimeError(value)  # a cell off the grid, a damaged file: named there
        values[name] = float(value)
    cell = tuple(int(v) for v in display.GetPropertyValue("PickedCell"))
    if cell == (0, 0, 0):
        return None
    active = int(display.GetPropertyValue("PickedActive"))
    corners = list(display.GetPropertyValue("PickedCorners"))
    corners = [tuple(corners[3 * n:3 * n + 3]) for n in range(8)] if active >= 0 else None
    point = tuple(display.GetPropertyValue("PickedPoint"))
    centre = tuple(sum(c[a] for c in corners) / 8 for a in range(3)) if corners else point
    return {"I": cell[0], "J": cell[1], "K": cell[2], "active": None if active < 0 else bool(active),
            "point": point, "depth": -centre[2], "centre": centre, "corners": corners, "values": values}


def _ask(view, display, name, value, nothing):
    """Sets `name` to `value` (answered at once from the last frame drawn), then back to
    `nothing`, so the same question can be asked again; renders once when no frame has been
    drawn yet (PicksDone unchanged)."""
    display.UpdatePropertyInformation()
    done = display.GetPropertyValue("PicksDone")
    setattr(display, name, value)
    display.UpdatePropertyInformation()
    if display.GetPropertyValue("PicksDone") == done:
        simple.Render(view)
    setattr(display, name, nothing)
    return _result(display)


def PickCell(x, y, view=None, display=None):
    """The original cell under display pixel (x, y) of `view` (the active view by default): a
    dict with I, J, K (from 1), active (None when unknown), point (the surface point picked),
    depth (of the cell's centre, positive down), centre, corners (eight (x, y, z), ECLIPSE's
    order, from the finest level) and values ({array: value} at the view's time; NaN where the
    cell has none); None over the background. The pick is made in the last frame drawn (what
    the user sees), with no new render."""
    view, display = _surface(view, display)
    return _ask(view, display, "PickAt", [x, y], [-1, -1])


def InspectCell(i, j, k, view=None, display=None):
    """What PickCell returns, for cell (I, J, K) (from 1), with no pixel: point is its centre.
    A cell off the grid raises RuntimeError naming the file and the grid's size."""
    view, display = _surface(view, display)
    return _ask(view, display, "InspectCell", [i, j, k], [0, 0, 0])


def SelectCell(i, j, k, view=None, display=None, color=(1.0, 0.1, 0.1)):
    """Outlines cell (I, J, K) in the view (its true corners, whatever level is drawn; a
    'Selected Cell' source in the pipeline browser, replaced by the next selection) and returns
    InspectCell's dict, or None if the file has no such cell's column."""
    view, display = _surface(view, display)
    cell = InspectCell(i, j, k, view, display)
    old = simple.FindSource("Selected Cell")
    if old is not None:
        simple.Delete(old)
    if cell is None or cell["corners"] is None:
        return cell
    outline = simple.PolyLineSource(Points=[v for n in _OUTLINE_PATH for v in cell["corners"][n]])
    simple.RenameSource("Selected Cell", outline)
    shown = simple.Show(outline, view)
    shown.AmbientColor = shown.DiffuseColor = list(color)
    shown.LineWidth = 3
    simple.Render(view)
    return cell


def GoToCell(i, j, k, view=None, display=None, distance=None):
    """Flies the camera to cell (I, J, K): its centre becomes the focal point, seen from the
    camera's direction at `distance` (default: 25 times the cell's size), and the cell is
    selected (SelectCell). Returns its dict, or None when there is no such cell."""
    view, display = _surface(view, display)
    cell = SelectCell(i, j, k, view, display)
    if cell is None or cell["corners"] is None:
        return cell
    camera = view.GetActiveCamera()
    direction = camera.GetDirectionOfProjection()
    size = max(max(c[a] for c in cell["corners"]) - min(c[a] for c in cell["corners"]) for a in range(3))
    distance = distance or 25 * size
    centre = cell["centre"]
    camera.SetFocalPoint(centre)
    camera.SetPosition([centre[a] - distance * direction[a] for a in range(3)])
    view.CenterOfRotation = list(centre)
    simple.Render(view)
    return cell


def GoToPoint(x, y, depth, view=None, display=None, distance=None):
    """Flies the camera to map point (x, y) at `depth` (positive down; world coordinates as the
    view shows them), from the camera's direction at `distance` (default: the camera's
    distance now), and selects the cell the view then shows at its centre: the surface's cell
    there, in front of the point when the point lies inside the model. Returns that cell's
    dict, or None when the centre shows the background."""
    view, display = _surface(view, display)
    camera = view.GetActiveCamera()
    direction = camera.GetDirectionOfProjection()
    distance = distance or camera.GetDistance()
    focal = (x, y, -depth)
    camera.SetFocalPoint(focal)
    camera.SetPosition([focal[a] - distance * direction[a] for a in range(3)])
    view.CenterOfRotation = list(focal)
    simple.Render(view)
    width, height = view.ViewSize
    cell = PickCell(width // 2, height // 2, view, display)
    return None if cell is None else SelectCell(cell["I"], cell["J"], cell["K"], view, display)
