// VTK's XML readers behind read_vtu and read_vtp crash (SIGSEGV) on some damaged
// files inside their own parser (found by test_fuzz_vtk_xml); such a file is read in
// a child process first and is an input error naming the file, not a crash.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/error.hpp"
#include "common/files.hpp"
#include "common/mesh_data.hpp"

using namespace stentsim;
namespace fs = std::filesystem;

TEST(VtkXmlReading, AFileThatCrashesVtksParserIsAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_vtk_xml_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // The example stent ring with a field-data array of an unknown type ("Strings"):
  // VTK 9.1's ReadXMLInformation dereferences a null pointer on it.
  const fs::path ring = fs::path(STENTSIM_TEST_SOURCE_DIR) / "examples/data/stent_ring_3el.vtu";
  ASSERT_NO_THROW(read_vtu(ring.string()));
  std::string text = files::read_text(ring);
  const auto at = text.find("<Array type=\"String\"");
  ASSERT_NE(at, std::string::npos);
  text.insert(at + 19, "s");
  files::write_atomic(dir / "damaged.vtu", text);
  try {
    read_vtu((dir / "damaged.vtu").string());
    ADD_FAILURE() << "no error for a damaged .vtu";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("damaged.vtu: the VTK XML reader crashed on this file"), std::string::npos) << e.what();
  }
  // A folder or a missing file is named before any reader sees it.
  EXPECT_THROW(read_vtp(dir.string()), InputError);
  EXPECT_THROW(read_vtp((dir / "missing.vtp").string()), InputError);
  fs::remove_all(dir);
}
