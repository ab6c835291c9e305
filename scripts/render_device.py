#!/usr/bin/env python3
"""Offscreen PNGs of the device artifacts, for a visual check (issue 4).

Renders balloon.vtu (hex8 cells as a surface), stent.vtu (beam lines as tubes
of their SectionRadius), balloon_centerline.vtp and the lumen surface
(translucent) from three views: side, top and along the balloon axis, plus
a close-up of the stent on the balloon. Not part of CI.

Needs VTK's Python module and an X server; on Debian:
  apt-get install python3-vtk9 xvfb
  xvfb-run -a /usr/bin/python3 scripts/render_device.py --work CASE.work --out /tmp/render
or with ParaView (which conflicts with libvtk9-dev on Debian 12, so not on a build machine):
  xvfb-run -a pvpython scripts/render_device.py ...
(--work takes a case work folder; single files with --balloon, --stent,
--centerline, --lumen instead). Writes OUT_side.png, OUT_top.png,
OUT_axial.png, OUT_closeup.png and OUT_section.png (a 0.3 mm slab across the
device at the middle of the balloon centerline, seen along it).
"""
import argparse
import os

try:  # Debian python3-vtk9
    import vtk
except ImportError:  # ParaView's pvpython ships VTK as vtkmodules
    import vtkmodules.all as vtk


def read(path):
    r = vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def actor(source_port, color, opacity=1.0):
    m = vtk.vtkDataSetMapper()
    m.SetInputConnection(source_port)
    m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    a.GetProperty().SetColor(*color)
    a.GetProperty().SetOpacity(opacity)
    return a


def balloon_actor(path):
    grid = read(path)
    # Keep the hex8 volume cells (balloon.vtu also carries tagged boundary faces).
    keep = vtk.vtkIdTypeArray()
    for i in range(grid.GetNumberOfCells()):
        if grid.GetCellType(i) == vtk.VTK_HEXAHEDRON:
            keep.InsertNextValue(i)
    sel_node = vtk.vtkSelectionNode()
    sel_node.SetFieldType(vtk.vtkSelectionNode.CELL)
    sel_node.SetContentType(vtk.vtkSelectionNode.INDICES)
    sel_node.SetSelectionList(keep)
    sel = vtk.vtkSelection()
    sel.AddNode(sel_node)
    ext = vtk.vtkExtractSelection()
    ext.SetInputData(0, grid)
    ext.SetInputData(1, sel)
    surf = vtk.vtkDataSetSurfaceFilter()
    surf.SetInputConnection(ext.GetOutputPort())
    a = actor(surf.GetOutputPort(), (0.35, 0.55, 0.95))
    a.GetProperty().EdgeVisibilityOn()
    a.GetProperty().SetEdgeColor(0.15, 0.25, 0.5)
    return a, grid


def stent_actor(path):
    grid = read(path)
    radius = grid.GetCellData().GetArray("SectionRadius").GetValue(0)
    geo = vtk.vtkGeometryFilter()
    geo.SetInputData(grid)
    tube = vtk.vtkTubeFilter()
    tube.SetInputConnection(geo.GetOutputPort())
    tube.SetRadius(radius)
    tube.SetNumberOfSides(12)
    return actor(tube.GetOutputPort(), (0.8, 0.8, 0.82)), grid


def polydata_actor(path, color, opacity=1.0, line_width=None):
    pd = read(path)
    src = vtk.vtkTrivialProducer()
    src.SetOutput(pd)
    a = actor(src.GetOutputPort(), color, opacity)
    if line_width:
        a.GetProperty().SetLineWidth(line_width)
    return a, pd


def render(actors, out, camera_setup, zoom=1.0, size=(1400, 800), section=None):
    ren = vtk.vtkRenderer()
    ren.SetBackground(1, 1, 1)
    for a in actors:
        ren.AddActor(a)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(*size)
    win.AddRenderer(ren)
    cam = ren.GetActiveCamera()
    camera_setup(cam)
    if section is None:
        ren.ResetCamera()  # keeps the view direction, fits the actors
        cam.Zoom(zoom)
        ren.ResetCameraClippingRange()
    else:  # near plane through the focal point: a slab `section` mm thick across the device
        d = cam.GetDistance()
        cam.SetClippingRange(d, d + section)
    win.Render()
    shot = vtk.vtkWindowToImageFilter()
    shot.SetInput(win)
    shot.Update()
    w = vtk.vtkPNGWriter()
    w.SetFileName(out)
    w.SetInputConnection(shot.GetOutputPort())
    w.Write()
    print("wrote", out)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--work", help="case work folder (balloon/, stent/, placement/, segmentation/)")
    p.add_argument("--balloon")
    p.add_argument("--stent")
    p.add_argument("--centerline", help="balloon_centerline.vtp")
    p.add_argument("--lumen", help="lumen.vtp")
    p.add_argument("--out", required=True, help="PNG file prefix")
    a = p.parse_args()
    if a.work:
        a.balloon = a.balloon or os.path.join(a.work, "balloon", "balloon.vtu")
        a.stent = a.stent or os.path.join(a.work, "stent", "stent.vtu")
        for attr, rel in (("centerline", "placement/balloon_centerline.vtp"), ("lumen", "segmentation/lumen.vtp")):
            f = os.path.join(a.work, rel)
            if getattr(a, attr) is None and os.path.exists(f):
                setattr(a, attr, f)

    balloon, bgrid = balloon_actor(a.balloon)
    stent, _ = stent_actor(a.stent)
    device = [balloon, stent]
    extra = []
    axis_pd = None
    if a.centerline:
        act, axis_pd = polydata_actor(a.centerline, (0.9, 0.1, 0.1), line_width=3)
        extra.append(act)
    if a.lumen:
        extra.append(polydata_actor(a.lumen, (0.95, 0.6, 0.5), opacity=0.25)[0])

    # View axes from the balloon's bounding box: its longest extent is "along".
    pts = [bgrid.GetPoint(i) for i in range(bgrid.GetNumberOfPoints())]
    centre = [sum(c) / len(pts) for c in zip(*pts)]
    bounds = bgrid.GetBounds()
    ext = [bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]]
    ax = max(range(3), key=lambda i: ext[i])

    def view(direction, up):
        def setup(cam):
            cam.SetFocalPoint(*centre)
            d = 40.0
            cam.SetPosition(*[centre[i] + d * direction[i] for i in range(3)])
            cam.SetViewUp(*up)
            cam.SetViewAngle(30)
        return setup

    # Side: perpendicular to the long axis; top: the other perpendicular; axial: along it.
    perp = [(ax + 1) % 3, (ax + 2) % 3]
    e = lambda i: [1.0 if j == i else 0.0 for j in range(3)]
    scenes = {
        "side": (device + extra, view(e(perp[0]), e(perp[1])), 1.0),
        "top": (device + extra, view(e(perp[1]), e(ax)), 1.0),
        "axial": (device + extra, view(e(ax), e(perp[1])), 1.0),
        "closeup": (device, view([0.6 * e(perp[0])[i] + 0.2 * e(perp[1])[i] for i in range(3)], e(perp[1])), 2.5),
    }
    for name, (actors, setup, zoom) in scenes.items():
        render(actors, "%s_%s.png" % (a.out, name), setup, zoom)

    # Cross-section at the device's middle, looking along the balloon axis
    # (the placement's centerline, else the long box axis): lumen, balloon
    # wall and strut sections beyond the cut.
    if axis_pd is not None and axis_pd.GetNumberOfPoints() > 2:
        n = axis_pd.GetNumberOfPoints()
        mid = axis_pd.GetPoint(n // 2)
        p0, p1 = axis_pd.GetPoint(n // 2 - 1), axis_pd.GetPoint(n // 2 + 1)
        t = [p1[i] - p0[i] for i in range(3)]
    else:
        mid, t = centre, e(ax)
    norm = sum(v * v for v in t) ** 0.5
    t = [v / norm for v in t]
    up = e(perp[1]) if abs(t[perp[1]]) < 0.9 else e(perp[0])

    def section_view(cam):
        cam.SetFocalPoint(*mid)
        cam.SetPosition(*[mid[i] - 5.0 * t[i] for i in range(3)])
        cam.SetViewUp(*up)
        cam.SetViewAngle(30)

    # 5 mm away at 30 degrees: about 2.7 mm across the view.
    render(device + extra, "%s_section.png" % a.out, section_view, section=0.3)


if __name__ == "__main__":
    main()
