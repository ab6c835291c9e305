// Mutation fuzzing of the VTK XML readers behind read_vtu and read_vtp (scene meshes,
// stent and fiber-frame files, the stand-alone tools' inputs): each mutant either
// reads, with every cell inside its points and every array sized to them, or is an
// InputError naming the file. VTK's parser crashes on some mutants in-process; the
// readers read each file in a child process first (check_vtk_xml_file). Seeds are
// written uncompressed (raw appended and ASCII), so mutants reach the parser and the
// data instead of all failing zlib, plus the compressed file as stentsim writes it,
// mutated as bytes and re-sealed: the decoded arrays (points, connectivity, offsets,
// cell types, data arrays) mutated in memory, then written with zlib again.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "common/files.hpp"
#include "common/mesh_data.hpp"
#include "tests/fuzz/mutation.hpp"

using namespace stentsim;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/data";

// `in` written again by VTK's own writer, uncompressed, raw appended or ASCII.
template <class Reader, class Writer>
std::string rewritten(const fs::path& in, const fs::path& out, bool ascii) {
  vtkNew<Reader> r;
  r->SetFileName(in.c_str());
  r->Update();
  vtkNew<Writer> w;
  w->SetInputData(r->GetOutput());
  w->SetFileName(out.c_str());
  w->SetCompressorTypeToNone();
  if (ascii) {
    w->SetDataModeToAscii();
  } else {
    w->SetDataModeToAppended();
    w->EncodeAppendedDataOff();
  }
  w->Write();
  return files::read_text(out);
}

// One decoded array of `g` mutated in place (its length kept), chosen by `gen`.
void mutate_an_array(vtkUnstructuredGrid* g, std::mt19937& gen) {
  std::vector<vtkDataArray*> arrays = {g->GetPoints()->GetData(), g->GetCells()->GetConnectivityArray(),
                                       g->GetCells()->GetOffsetsArray(), g->GetCellTypesArray()};
  for (int i = 0; i < g->GetPointData()->GetNumberOfArrays(); ++i) arrays.push_back(g->GetPointData()->GetArray(i));
  for (int i = 0; i < g->GetCellData()->GetNumberOfArrays(); ++i) arrays.push_back(g->GetCellData()->GetArray(i));
  std::erase(arrays, nullptr);
  vtkDataArray* a = arrays[std::uniform_int_distribution<std::size_t>(0, arrays.size() - 1)(gen)];
  const std::size_t bytes = static_cast<std::size_t>(a->GetNumberOfValues()) * static_cast<std::size_t>(a->GetDataTypeSize());
  if (bytes == 0) return;
  auto* p = static_cast<char*>(a->GetVoidPointer(0));
  std::string m = fuzz::mutate(std::string(p, bytes), gen);
  m.resize(bytes, '\0');
  std::memcpy(p, m.data(), bytes);
  a->Modified();
}

void check(const MeshData& m) {
  for (auto id : m.connectivity) ASSERT_TRUE(id >= 0 && static_cast<std::size_t>(id) < m.points.size());
}

}  // namespace

TEST(VtkXmlFuzz, MutantsReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_xml_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const int n = fuzz::iterations();
  std::mt19937 gen(20261208);
  const fs::path balloon = kData / "balloon_3mm.vtu", stent = kData / "stent_ring_3el.vtu";
  const std::vector<std::pair<std::string, std::string>> vtu = {
      {"vtu raw", rewritten<vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter>(stent, dir / "seed.vtu", false)},
      {"vtu ascii", rewritten<vtkXMLUnstructuredGridReader, vtkXMLUnstructuredGridWriter>(stent, dir / "seed.vtu", true)},
      {"vtu zlib", files::read_text(balloon)}};
  for (const auto& [format, seed] : vtu)
    fuzz::judge(format, n, [&](int) { fuzz::write_file(dir / "t.vtu", fuzz::mutate(seed, gen)); return dir / "t.vtu"; },
                [](const fs::path& f) { check(read_vtu(f.string())); });
  {
    vtkNew<vtkXMLUnstructuredGridReader> r;
    r->SetFileName(balloon.c_str());
    r->Update();
    const auto t = fuzz::judge("vtu zlib sealed", n, [&](int) {
      vtkNew<vtkUnstructuredGrid> g;
      g->DeepCopy(r->GetOutput());
      mutate_an_array(g, gen);
      vtkNew<vtkXMLUnstructuredGridWriter> w;
      w->SetInputData(g);
      w->SetFileName((dir / "t.vtu").c_str());
      w->SetCompressorTypeToZLib();
      w->SetDataModeToAppended();
      w->Write();
      return dir / "t.vtu";
    }, [](const fs::path& f) { check(read_vtu(f.string())); });
    EXPECT_GT(t.read, n / 4);  // the mutants get past zlib: most read
    EXPECT_GT(t.refused, 0);   // and some reach the index checks
  }
  // A poly data file: the stent's surface-free centerline is no .vtp; the balloon's cells as polys are.
  MeshData surface;
  const MeshData b = read_vtu(balloon.string());
  surface.points = b.points;
  for (std::size_t c = 0; c < b.num_cells(); ++c) {
    const auto nodes = b.cell(c);
    surface.add_cell(CellType::quad, {nodes[0], nodes[1], nodes[2], nodes[3]});
  }
  write_vtp((dir / "zseed.vtp").string(), surface);
  const std::string vtp_raw = rewritten<vtkXMLPolyDataReader, vtkXMLPolyDataWriter>(dir / "zseed.vtp", dir / "seed.vtp", false);
  fuzz::judge("vtp raw", n, [&](int) { fuzz::write_file(dir / "t.vtp", fuzz::mutate(vtp_raw, gen)); return dir / "t.vtp"; },
              [](const fs::path& f) { check(read_vtp(f.string())); });
  fs::remove_all(dir);
}
