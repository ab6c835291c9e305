// Mutation fuzzing of the VTK XML readers behind read_vtu and read_vtp (scene meshes,
// stent and fiber-frame files, the stand-alone tools' inputs): each mutant either
// reads, with every cell inside its points and every array sized to them, or is an
// InputError naming the file. VTK's parser crashes on some mutants in-process; the
// readers read each file in a child process first (check_vtk_xml_file). Seeds are
// written uncompressed (raw appended and ASCII), so mutants reach the parser and the
// data instead of all failing zlib, plus the compressed file as stentsim writes it.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <filesystem>
#include <string>

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
