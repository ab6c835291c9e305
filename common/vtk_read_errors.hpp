#pragma once
// VTK readers report a damaged or short file through an error event and often
// return what they read so far (zeros for missing voxels, cells that refer past
// their arrays). Observing the event, a reader's first error message is kept so
// that the adapter can refuse the output and name the file. Included only by
// the VTK adapter files (common/vtk_io.cpp, segmentation_io/*_vtk.cpp).
#include <vtkCommand.h>
#include <vtkObject.h>

#include <algorithm>
#include <string>

namespace stentsim {

class VtkReadErrors : public vtkCommand {
 public:
  static VtkReadErrors* New() { return new VtkReadErrors; }
  void Execute(vtkObject*, unsigned long, void* data) override {
    if (first.empty() && data) {
      first = static_cast<const char*>(data);
      std::replace(first.begin(), first.end(), '\n', ' ');
    }
  }
  /// The first error message; empty when none was reported.
  std::string first;
};

}  // namespace stentsim
