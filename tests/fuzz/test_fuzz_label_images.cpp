// Mutation fuzzing of the label-image readers (NIfTI plain and gzip, NRRD raw
// and gzip, MetaImage header, detached raw data, single file plain and
// compressed): each mutant of a small cylinder label either gives a surface or
// an InputError naming the file. Compressed files are re-sealed: their decoded
// bytes (or their header) are mutated and the data compressed again, so
// mutants reach the parsers instead of all failing zlib's check.
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkImageData.h>
#include <vtkMetaImageWriter.h>
#include <vtkNIFTIImageWriter.h>
#include <vtkSmartPointer.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "segmentation_io/label_image.hpp"
#include "tests/fuzz/mutation.hpp"

using namespace stentsim;
using namespace stentsim::segmentation;
namespace fs = std::filesystem;

namespace {

constexpr int kDim[3] = {14, 14, 30};
constexpr double kSpacing = 0.5;

// Label 1 inside a cylinder of 3.5 voxels' radius along z, slices 3..26.
vtkSmartPointer<vtkImageData> cylinder() {
  auto im = vtkSmartPointer<vtkImageData>::New();
  im->SetDimensions(kDim[0], kDim[1], kDim[2]);
  im->SetSpacing(kSpacing, kSpacing, kSpacing);
  im->SetOrigin(1, 2, 3);
  im->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* p = static_cast<unsigned char*>(im->GetScalarPointer());
  for (int k = 0; k < kDim[2]; ++k)
    for (int j = 0; j < kDim[1]; ++j)
      for (int i = 0; i < kDim[0]; ++i)
        p[i + kDim[0] * (j + kDim[1] * k)] = k >= 3 && k <= 26 && std::hypot(i - 6.5, j - 6.5) < 3.5 ? 1 : 0;
  return im;
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string nifti(const fs::path& dir) {
  auto w = vtkSmartPointer<vtkNIFTIImageWriter>::New();
  w->SetInputData(cylinder());
  w->SetFileName((dir / "seed.nii").c_str());
  w->Write();
  return slurp(dir / "seed.nii");
}

std::string nrrd_header(const std::string& encoding) {
  return "NRRD0004\ntype: uint8\ndimension: 3\nspace: left-posterior-superior\nsizes: 14 14 30\n"
         "space directions: (0.5,0,0) (0,0.5,0) (0,0,0.5)\nkind: domain domain domain\nendian: little\n"
         "encoding: " + encoding + "\nspace origin: (1,2,3)\n\n";
}

std::string voxels() {
  auto im = cylinder();
  const auto* p = static_cast<const char*>(im->GetScalarPointer());
  return std::string(p, static_cast<std::size_t>(kDim[0] * kDim[1] * kDim[2]));
}

std::string nrrd() { return nrrd_header("raw") + voxels(); }

// MetaImage: header seed.mhd with ElementDataFile seed.raw, or a single .mha.
void metaimage(const fs::path& file) {
  auto w = vtkSmartPointer<vtkMetaImageWriter>::New();
  w->SetInputData(cylinder());
  w->SetFileName(file.c_str());
  if (file.extension() == ".mhd") w->SetRAWFileName((file.parent_path() / "seed.raw").c_str());
  w->SetCompression(false);
  w->Write();
}

std::string gzip(const std::string& data) {
  z_stream z{};
  deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);  // 15 + 16: gzip wrapper
  std::string out(deflateBound(&z, static_cast<uLong>(data.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

// A zlib stream (MetaImage's CompressedData).
std::string zlib(const std::string& data) {
  uLongf size = compressBound(static_cast<uLong>(data.size()));
  std::string out(size, '\0');
  compress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(data.data()), static_cast<uLong>(data.size()));
  out.resize(size);
  return out;
}

// A single-file MetaImage with zlib data, its CompressedDataSize true to `data`.
std::string mha_zlib(const std::string& header, const std::string& data) {
  const std::string z = zlib(data);
  return header + "CompressedDataSize = " + std::to_string(z.size()) + "\nElementDataFile = LOCAL\n" + z;
}

void read_label_image(const fs::path& f) {
  LabelSurfaceOptions o;
  o.labels = {1};
  (void)nifti_spatial_units(f);
  const TriSurface s = label_image_surface(f, o);
  for (const auto& t : s.triangles)
    for (int v : t) ASSERT_TRUE(v >= 0 && static_cast<std::size_t>(v) < s.points.size()) << f;
}

}  // namespace

TEST(LabelImageFuzz, MutantsReadOrFailWithAnInputError) {
  const fs::path dir = fs::temp_directory_path() / ("stentsim_label_fuzz_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const int n = fuzz::iterations();
  std::mt19937 gen(20261203);
  const std::string nii = nifti(dir);
  fuzz::judge("nii", n, [&](int) { fuzz::write_file(dir / "t.nii", fuzz::mutate(nii, gen)); return dir / "t.nii"; },
              read_label_image);
  fuzz::judge("nii.gz", n, [&](int) { fuzz::write_file(dir / "t.nii.gz", gzip(fuzz::mutate(nii, gen))); return dir / "t.nii.gz"; },
              read_label_image);
  const std::string nrrd_seed = nrrd();
  fuzz::judge("nrrd", n, [&](int) { fuzz::write_file(dir / "t.nrrd", fuzz::mutate(nrrd_seed, gen)); return dir / "t.nrrd"; },
              read_label_image);
  metaimage(dir / "seed.mhd");  // writes seed.raw beside it, which the mutated headers name
  const std::string mhd = slurp(dir / "seed.mhd"), raw = slurp(dir / "seed.raw");
  fuzz::judge("mhd", n, [&](int) { fuzz::write_file(dir / "t.mhd", fuzz::mutate(mhd, gen)); return dir / "t.mhd"; },
              read_label_image);
  fuzz::judge("mhd raw", n, [&](int) {
    fuzz::write_file(dir / "seed.raw", fuzz::mutate(raw, gen));
    fuzz::write_file(dir / "t.mhd", mhd);
    return dir / "t.mhd";
  }, read_label_image);
  metaimage(dir / "seed.mha");
  const std::string mha = slurp(dir / "seed.mha");
  fuzz::judge("mha", n, [&](int) { fuzz::write_file(dir / "t.mha", fuzz::mutate(mha, gen)); return dir / "t.mha"; },
              read_label_image);
  // Re-sealed: half the mutants change the header, half the decoded voxels; the data is
  // compressed (again) after the mutation.
  const std::string vox = voxels();
  std::uniform_int_distribution<int> coin(0, 1);
  const std::string nrrd_gz_header = nrrd_header("gzip");
  fuzz::write_file(dir / "t.nrrd", nrrd_gz_header + gzip(vox));
  ASSERT_NO_THROW(read_label_image(dir / "t.nrrd")) << "the gzip NRRD seed must read";
  const auto nrrd_gz = fuzz::judge("nrrd gzip", n, [&](int) {
    const bool header = coin(gen);
    fuzz::write_file(dir / "t.nrrd", (header ? fuzz::mutate(nrrd_gz_header, gen) : nrrd_gz_header) + gzip(header ? vox : fuzz::mutate(vox, gen)));
    return dir / "t.nrrd";
  }, read_label_image);
  const std::string mha_header =
      "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\nCompressedData = True\n"
      "Offset = 1 2 3\nElementSpacing = 0.5 0.5 0.5\nDimSize = 14 14 30\nElementType = MET_UCHAR\n";
  fuzz::write_file(dir / "t.mha", mha_zlib(mha_header, vox));
  ASSERT_NO_THROW(read_label_image(dir / "t.mha")) << "the compressed MetaImage seed must read";
  const auto mha_z = fuzz::judge("mha zlib", n, [&](int) {
    const bool header = coin(gen);
    fuzz::write_file(dir / "t.mha", mha_zlib(header ? fuzz::mutate(mha_header, gen) : mha_header, header ? vox : fuzz::mutate(vox, gen)));
    return dir / "t.mha";
  }, read_label_image);
  // Re-sealed mutants reach the voxels: most of them read (a changed label is still a label image).
  EXPECT_GT(nrrd_gz.read, n / 4);
  EXPECT_GT(mha_z.read, n / 4);
  fs::remove_all(dir);
}
