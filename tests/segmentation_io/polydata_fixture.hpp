#pragma once
// A TriSurface as a vtkPolyData (points and triangle polygons), for tests that
// write files with VTK's own writers.
#include <vtkCellArray.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "segmentation_io/triangle_surface.hpp"

namespace stentsim::segmentation {

inline vtkSmartPointer<vtkPolyData> to_polydata(const TriSurface& s) {
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  auto pts = vtkSmartPointer<vtkPoints>::New();
  for (const auto& p : s.points) pts->InsertNextPoint(p.x(), p.y(), p.z());
  pd->SetPoints(pts);
  auto polys = vtkSmartPointer<vtkCellArray>::New();
  for (const auto& t : s.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  pd->SetPolys(polys);
  return pd;
}

}  // namespace stentsim::segmentation
