#include "segmentation_io/image_header_checks.hpp"

#include <fmt/format.h>
#include <zlib.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.hpp"

namespace stentsim::segmentation {
namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return {};
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

/// The bytes of `file` from `offset` on, through gzip when they are compressed
/// (gzread passes plain bytes as they are): the first `keep` of them and how many
/// there are, counted up to `limit` (a gzip bomb is not read to its end).
struct Decoded {
  std::string bytes;
  double total = 0;
};

Decoded decoded(const std::filesystem::path& file, double offset, std::size_t keep, double limit) {
  const int fd = ::open(file.c_str(), O_RDONLY);
  if (fd < 0 || ::lseek(fd, static_cast<off_t>(offset), SEEK_SET) < 0) {
    if (fd >= 0) ::close(fd);
    throw InputError(fmt::format("{}: cannot be opened", file.string()));
  }
  gzFile g = gzdopen(fd, "rb");
  if (!g) {
    ::close(fd);
    throw InputError(fmt::format("{}: cannot be opened", file.string()));
  }
  Decoded d;
  std::vector<char> buf(1 << 16);
  while (d.total < limit) {
    const int n = gzread(g, buf.data(), static_cast<unsigned>(buf.size()));
    if (n <= 0) break;
    if (d.bytes.size() < keep) d.bytes.append(buf.data(), std::min<std::size_t>(static_cast<std::size_t>(n), keep - d.bytes.size()));
    d.total += n;
  }
  gzclose(g);
  return d;
}

/// The bytes a zlib or gzip stream in `file` from `offset` on inflates to, counted up to `limit`.
double inflated(const std::filesystem::path& file, double offset, double limit) {
  std::ifstream in(file, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(offset));
  z_stream z{};
  if (!in || inflateInit2(&z, 15 + 32) != Z_OK) return 0;  // 15 + 32: zlib or gzip header
  std::vector<char> src(1 << 16), dst(1 << 16);
  double total = 0;
  int rc = Z_OK;
  while (rc == Z_OK && total < limit) {
    if (z.avail_in == 0) {
      in.read(src.data(), static_cast<std::streamsize>(src.size()));
      if (in.gcount() <= 0) break;
      z.next_in = reinterpret_cast<Bytef*>(src.data());
      z.avail_in = static_cast<uInt>(in.gcount());
    }
    z.next_out = reinterpret_cast<Bytef*>(dst.data());
    z.avail_out = static_cast<uInt>(dst.size());
    rc = inflate(&z, Z_NO_FLUSH);
    total += static_cast<double>(dst.size() - z.avail_out);
  }
  inflateEnd(&z);
  return total;
}

// The voxel bytes `need` against the data in `file` after `header_end` (data_file empty)
// or in the detached `data_file` (relative to the header's folder).
void check_data_size(const std::filesystem::path& file, const char* format, const std::string& fields, double need,
                     const std::string& data_file, const char* data_key, std::uintmax_t header_end) {
  std::uintmax_t have = 0;
  std::string where = file.string();
  if (data_file.empty()) {
    have = std::filesystem::file_size(file) - std::min(header_end, std::filesystem::file_size(file));
  } else {
    std::filesystem::path data = data_file;
    if (data.is_relative()) data = file.parent_path() / data;
    if (!std::filesystem::is_regular_file(data))
      throw InputError(fmt::format("{}: {} {} is {} (a regular file of voxel data is expected)", file.string(), data_key,
                                   data_file, std::filesystem::exists(data) ? "not a regular file (a device or a pipe?)" : "missing"));
    have = std::filesystem::file_size(data);
    where = data.string();
  }
  if (static_cast<double>(have) < need)
    throw InputError(fmt::format("{}: the {} voxel data is cut short or damaged: {} need {:.0f} bytes, {} has {}", file.string(),
                                 format, fields, need, where, have));
}

constexpr std::size_t kNifti1 = 348, kNifti2 = 540;

template <class T>
T field(const std::string& h, std::size_t at, bool swap) {
  T v;
  char b[sizeof(T)];
  for (std::size_t i = 0; i < sizeof(T); ++i) b[i] = h.at(at + i);
  if (swap) std::reverse(b, b + sizeof(T));
  std::memcpy(&v, b, sizeof(T));
  return v;
}

// Voxel types a label image can hold, with their bits per voxel.
const std::map<int, int> kVoxelBits = {{2, 8},    {4, 16},   {8, 32},    {16, 32},   {64, 64},
                                       {256, 8},  {512, 16}, {768, 32},  {1024, 64}, {1280, 64}};


/// A strict decimal integer ("14", not "14abc" or "1e3").
bool integer(const std::string& s, long long& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  v = std::strtoll(s.c_str(), &end, 10);
  return errno == 0 && end && *end == '\0';
}

/// Whitespace-separated finite numbers; false for anything else.
bool numbers(const std::string& s, std::vector<double>& v) {
  std::istringstream in(s);
  v.clear();
  for (std::string w; in >> w;) {
    char* end = nullptr;
    const double d = std::strtod(w.c_str(), &end);
    if (!end || *end != '\0' || !std::isfinite(d)) return false;
    v.push_back(d);
  }
  return true;
}

/// "(a,b,c)" with three finite numbers.
bool vector3(const std::string& s) {
  if (s.size() < 2 || s.front() != '(' || s.back() != ')') return false;
  std::string inner = s.substr(1, s.size() - 2);
  std::replace(inner.begin(), inner.end(), ',', ' ');
  std::vector<double> v;
  return std::count(s.begin(), s.end(), ',') == 2 && numbers(inner, v) && v.size() == 3;
}

}  // namespace

void check_nifti_header(const std::filesystem::path& file) {
  const std::string name = file.string();
  const std::string h = decoded(file, 0, kNifti2, kNifti2).bytes;
  if (h.size() < kNifti1)
    throw InputError(fmt::format("{}: the NIfTI header is cut short ({} bytes; a NIfTI-1 header has 348)", name, h.size()));
  const auto size1 = field<std::int32_t>(h, 0, false), size1_swapped = field<std::int32_t>(h, 0, true);
  const bool two = size1 == static_cast<std::int32_t>(kNifti2) || size1_swapped == static_cast<std::int32_t>(kNifti2);
  const bool swap = size1 != static_cast<std::int32_t>(two ? kNifti2 : kNifti1);
  if (!two && size1 != static_cast<std::int32_t>(kNifti1) && size1_swapped != static_cast<std::int32_t>(kNifti1))
    throw InputError(fmt::format("{}: sizeof_hdr is {}; a NIfTI header gives 348 (NIfTI-1) or 540 (NIfTI-2)", name, size1));
  if (two && h.size() < kNifti2)
    throw InputError(fmt::format("{}: the NIfTI-2 header is cut short ({} bytes of 540)", name, h.size()));
  const std::string magic = two ? h.substr(4, 4) : h.substr(344, 4);
  if (magic != std::string(two ? "n+2" : "n+1", 4))
    throw InputError(fmt::format("{}: NIfTI magic is not '{}' (a single-file .nii; a .hdr/.img pair is not read)", name,
                                 two ? "n+2" : "n+1"));
  const int datatype = two ? field<std::int16_t>(h, 12, swap) : field<std::int16_t>(h, 70, swap);
  const int bitpix = two ? field<std::int16_t>(h, 14, swap) : field<std::int16_t>(h, 72, swap);
  const auto type = kVoxelBits.find(datatype);
  if (type == kVoxelBits.end())
    throw InputError(fmt::format("{}: NIfTI datatype {} is not an integer or real voxel type a label image can hold", name, datatype));
  if (bitpix != type->second)
    throw InputError(fmt::format("{}: NIfTI bitpix {} does not match datatype {} ({} bits)", name, bitpix, datatype, type->second));
  double dim[8], pixdim[8];
  for (int i = 0; i < 8; ++i) {
    dim[i] = two ? static_cast<double>(field<std::int64_t>(h, 16 + 8 * i, swap)) : field<std::int16_t>(h, 40 + 2 * i, swap);
    pixdim[i] = two ? field<double>(h, 104 + 8 * i, swap) : field<float>(h, 76 + 4 * i, swap);
  }
  if (dim[0] < 1 || dim[0] > 7)
    throw InputError(fmt::format("{}: NIfTI dim[0] (the number of axes) is {:g}; expected 1 to 7", name, dim[0]));
  double need = type->second / 8.0;
  for (int i = 1; i <= static_cast<int>(dim[0]); ++i) {
    if (dim[i] < 1) throw InputError(fmt::format("{}: NIfTI dim[{}] is {:g}; every axis needs at least one voxel", name, i, dim[i]));
    if (!std::isfinite(pixdim[i]))
      throw InputError(fmt::format("{}: NIfTI pixdim[{}] is not a finite number", name, i));
    // VTK's reader reads a zero voxel size as given (a flat image whose surface
    // collapses); the three spatial axes need a positive one.
    if (i <= 3 && pixdim[i] == 0)
      throw InputError(fmt::format("{}: NIfTI pixdim[{}] is 0: axis {} has zero spacing; the voxel size must be positive "
                                   "(a header written without its voxel size?)", name, i, i));
    need *= dim[i];
  }
  if (!std::isfinite(pixdim[0])) throw InputError(fmt::format("{}: NIfTI pixdim[0] (qfac) is not a finite number", name));
  const double offset = two ? static_cast<double>(field<std::int64_t>(h, 168, swap)) : field<float>(h, 108, swap);
  const double header = two ? kNifti2 + 4 : kNifti1 + 4;
  if (!std::isfinite(offset) || offset < header)
    throw InputError(fmt::format("{}: NIfTI vox_offset {:g} lies inside the header (expected at least {:g})", name, offset, header));
  // Quaternion, offsets and sform rows: finite wherever a code selects them.
  const int qform = two ? field<std::int32_t>(h, 344, swap) : field<std::int16_t>(h, 252, swap);
  const int sform = two ? field<std::int32_t>(h, 348, swap) : field<std::int16_t>(h, 254, swap);
  for (int i = 0; i < 6 && qform > 0; ++i)
    if (!std::isfinite(two ? field<double>(h, 352 + 8 * i, swap) : field<float>(h, 256 + 4 * i, swap)))
      throw InputError(fmt::format("{}: NIfTI qform (quatern_b..qoffset_z) holds a non-finite number", name));
  for (int i = 0; i < 12 && sform > 0; ++i)
    if (!std::isfinite(two ? field<double>(h, 400 + 8 * i, swap) : field<float>(h, 280 + 4 * i, swap)))
      throw InputError(fmt::format("{}: NIfTI sform (srow_x..srow_z) holds a non-finite number", name));
  const double have = decoded(file, 0, 0, offset + need).total;
  if (have < offset + need)
    throw InputError(fmt::format("{}: the NIfTI voxel data is cut short or damaged: dim and datatype need {:.0f} bytes from "
                                 "vox_offset {:g}, the file holds {:.0f}{}", name, need, offset, std::max(0.0, have - offset),
                                 name.ends_with(".gz") ? " once decompressed" : ""));
}


void check_nrrd_header(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(fmt::format("{}: cannot be opened", name));
  std::string line;
  if (!std::getline(f, line) || line.compare(0, 4, "NRRD") != 0) throw InputError(fmt::format("{}: not a NRRD file (no NRRD magic)", name));
  auto bad = [&](const std::string& field, const std::string& value, const std::string& expected) {
    return InputError(fmt::format("{}: {}: '{}' -- expected {}", name, field, value, expected));
  };
  long long dimension = 0;
  std::vector<double> sizes;
  std::string type, encoding = "raw", data_file;
  // Fields as VTK's reader splits them: at the first ": ", up to the first empty line.
  for (int n = 0; std::getline(f, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) break;  // attached data follows
    // VTK's reader takes the header for a C string: a NUL ends it and the data offset is lost.
    if (line.find('\0') != std::string::npos) throw InputError(fmt::format("{}: the NRRD header holds a NUL byte (line {})", name, n + 2));
    if (n > 10000) throw InputError(fmt::format("{}: the NRRD header has no end (no empty line in its first 10,000 lines)", name));
    if (line[0] == '#') continue;
    const auto delim = line.find(": ");
    if (delim == std::string::npos) continue;  // "key:=value" pairs, which the reader skips
    const std::string field = line.substr(0, delim), value = trim(line.substr(delim + 2));
    std::vector<double> v;
    if (field == "dimension") {
      if (!integer(value, dimension) || dimension != 3) throw bad(field, value, "3 (a label image is a 3-D scalar image)");
    } else if (field == "space dimension") {
      long long d = 0;
      if (!integer(value, d) || d != 3) throw bad(field, value, "3");
    } else if (field == "sizes" || field == "spacings") {
      // VTK's reader sizes these lists by the dimension read before them.
      if (dimension != 3) throw InputError(fmt::format("{}: NRRD field '{}' comes before 'dimension: 3'", name, field));
      if (!numbers(value, v) || v.size() != 3) throw bad(field, value, "three numbers, one per axis");
      for (double d : v)
        if (field == "sizes" && (d < 1 || d != std::floor(d))) throw bad(field, value, "three positive whole counts");
      // VTK takes a first axis of spacing 0 for vector components; the other axes' zeros are named later.
      if (field == "spacings" && v[0] == 0)
        throw InputError(fmt::format("{}: spacings: '{}': axis 1 has zero spacing; the spacing must be positive", name, value));
      if (field == "sizes") sizes = v;
    } else if (field == "space directions") {
      std::istringstream in(value);
      int k = 0;
      for (std::string w; in >> w; ++k)
        if (!vector3(w)) throw bad(field, value, "three 3-vectors (x,y,z) of finite numbers, one per spatial axis");
      if (k != 3) throw bad(field, value, "three 3-vectors (x,y,z) of finite numbers, one per spatial axis");
    } else if (field == "space origin") {
      if (!vector3(value)) throw bad(field, value, "one vector (x,y,z) of finite numbers");
    } else if (field == "type") {
      type = value;
    } else if (field == "encoding") {
      encoding = value;
      std::transform(encoding.begin(), encoding.end(), encoding.begin(), [](unsigned char c) { return char(std::tolower(c)); });
      if (encoding == "gz") encoding = "gzip";
      // VTK 9.1 reads text voxels from the header's first byte, and uint8 text as characters.
      if (encoding != "raw" && encoding != "gzip") throw bad(field, value, "raw or gzip (text voxels are not read)");
    } else if (field == "data file" || field == "datafile") {
      std::istringstream in(value);
      std::vector<std::string> words;
      for (std::string w; in >> w;) words.push_back(w);
      if (words.size() != 1 || words[0] == "LIST" || value.find('%') != std::string::npos)
        throw bad(field, value, "one data file name (lists and patterns of slice files are not read)");
      data_file = value;
    } else if (field == "endian") {
      if (value != "little" && value != "big") throw bad(field, value, "little or big");
    }
  }
  static const std::map<std::string, double> kBytes = {
      {"signed char", 1}, {"int8", 1}, {"int8_t", 1}, {"uchar", 1}, {"unsigned char", 1}, {"uint8", 1}, {"uint8_t", 1},
      {"short", 2}, {"short int", 2}, {"signed short", 2}, {"signed short int", 2}, {"int16", 2}, {"int16_t", 2},
      {"ushort", 2}, {"unsigned short", 2}, {"unsigned short int", 2}, {"uint16", 2}, {"uint16_t", 2},
      {"int", 4}, {"signed int", 4}, {"int32", 4}, {"int32_t", 4}, {"uint", 4}, {"unsigned int", 4}, {"uint32", 4},
      {"uint32_t", 4}, {"longlong", 8}, {"long long", 8}, {"long long int", 8}, {"signed long long", 8},
      {"signed long long int", 8}, {"int64", 8}, {"int64_t", 8}, {"ulonglong", 8}, {"unsigned long long", 8},
      {"unsigned long long int", 8}, {"uint64", 8}, {"uint64_t", 8}, {"float", 4}, {"double", 8}};
  const auto bytes = kBytes.find(type);
  if (bytes == kBytes.end()) throw bad("type", type, "an integer or real voxel type (uint8, int16, float, ...)");
  if (dimension != 3 || sizes.empty()) throw InputError(fmt::format("{}: the NRRD header lacks 'dimension: 3' or 'sizes'", name));
  if (sizes[0] <= 9)
    throw InputError(fmt::format("{}: NRRD sizes: the first axis has {:g} voxels; VTK reads a first axis of 9 or fewer as vector "
                                 "components, so a label image needs at least 10 voxels along it", name, sizes[0]));
  double need = bytes->second;
  for (double d : sizes) need *= d;
  const auto at = f.tellg();
  const double header_end = at < 0 ? 0.0 : static_cast<double>(at);
  if (encoding == "raw") {
    check_data_size(file, "NRRD", "sizes and type " + type, need, data_file, "data file", static_cast<std::uintmax_t>(header_end));
    return;
  }
  std::filesystem::path data = data_file.empty() ? file : std::filesystem::path(data_file);
  if (data.is_relative()) data = file.parent_path() / data;
  if (!data_file.empty()) check_data_size(file, "NRRD", "a data file", 0, data_file, "data file", 0);
  const double have = decoded(data, data_file.empty() ? header_end : 0.0, 0, need).total;
  if (have < need)
    throw InputError(fmt::format("{}: the NRRD voxel data is cut short or damaged: sizes and type {} need {:.0f} bytes, the gzip "
                                 "data holds {:.0f}", name, type, need, have));
}

void check_metaimage_header(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream f(file, std::ios::binary);
  if (!f) throw InputError(fmt::format("{}: cannot be opened", name));
  auto bad = [&](const std::string& key, const std::string& value, const std::string& expected) {
    return InputError(fmt::format("{}: MetaImage {} = '{}' -- expected {}", name, key, value, expected));
  };
  long long ndims = 0, channels = 1, header_size = 0, compressed_size = -1;
  std::vector<double> dims;
  std::string type, data_file;
  bool compressed = false, text = false, ended = false;
  std::string line;
  for (int n = 0; std::getline(f, line); ++n) {
    if (n > 10000) throw InputError(fmt::format("{}: the MetaImage header has no ElementDataFile in its first 10,000 lines", name));
    const auto eq = line.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
    if (value.find('\0') != std::string::npos) throw bad(key, value, "text without NUL bytes");
    std::vector<double> v;
    // MetaIO sizes its array fields by NDims as read so far.
    auto array = [&](std::size_t count, bool nonzero) {
      if (ndims != 3) throw InputError(fmt::format("{}: MetaImage {} comes before NDims = 3", name, key));
      if (!numbers(value, v) || v.size() != count || (nonzero && std::count(v.begin(), v.end(), 0.0)))
        throw bad(key, value, fmt::format("{} finite{} numbers", count, nonzero ? " non-zero" : ""));
    };
    auto flag = [&]() {
      if (value != "True" && value != "False" && value != "true" && value != "false") throw bad(key, value, "True or False");
      return value == "True" || value == "true";
    };
    if (key == "NDims") {
      if (!integer(value, ndims) || ndims != 3) throw bad(key, value, "3 (a label image is a 3-D image)");
    } else if (key == "ObjectType") {
      if (value != "Image") throw bad(key, value, "Image");
    } else if (key == "DimSize") {
      array(3, true);
      for (double d : v)
        if (d < 1 || d != std::floor(d)) throw bad(key, value, "three positive whole counts");
      dims = v;
    } else if (key == "ElementSpacing" || key == "ElementSize") {
      array(3, true);
    } else if (key == "Offset" || key == "Origin" || key == "Position" || key == "CenterOfRotation") {
      array(3, false);
    } else if (key == "TransformMatrix" || key == "Rotation" || key == "Orientation") {
      array(9, false);
    } else if (key == "ElementNumberOfChannels") {
      if (!integer(value, channels) || channels < 1 || channels > 16) throw bad(key, value, "a channel count from 1 to 16");
    } else if (key == "ElementType") {
      type = value;
    } else if (key == "CompressedData") {
      compressed = flag();
    } else if (key == "CompressedDataSize") {
      if (!integer(value, compressed_size) || compressed_size < 1) throw bad(key, value, "a positive byte count");
    } else if (key == "BinaryData") {
      text = !flag();
    } else if (key == "BinaryDataByteOrderMSB" || key == "ElementByteOrderMSB") {
      flag();
    } else if (key == "HeaderSize") {
      if (!integer(value, header_size) || header_size < -1) throw bad(key, value, "a byte count, or -1 (the data at the file's end)");
    } else if (key == "ElementDataFile") {
      std::istringstream in(value);
      std::vector<std::string> words;
      for (std::string w; in >> w;) words.push_back(w);
      if (words.size() != 1 || words[0] == "LIST" || value.find('%') != std::string::npos)
        throw bad(key, value, "LOCAL or one data file name (lists and patterns of slice files are not read)");
      data_file = value;
      ended = true;
      break;  // the last header field; binary data may follow in a .mha
    }
  }
  if (!ended) throw InputError(fmt::format("{}: the MetaImage header has no ElementDataFile", name));
  if (ndims != 3 || dims.empty()) throw InputError(fmt::format("{}: the MetaImage header lacks NDims = 3 or DimSize", name));
  static const std::map<std::string, double> kBytes = {
      {"MET_CHAR", 1}, {"MET_UCHAR", 1}, {"MET_SHORT", 2}, {"MET_USHORT", 2}, {"MET_INT", 4},        {"MET_UINT", 4},
      {"MET_LONG", 4}, {"MET_ULONG", 4}, {"MET_FLOAT", 4}, {"MET_DOUBLE", 8}, {"MET_LONG_LONG", 8}, {"MET_ULONG_LONG", 8}};
  const auto bytes = kBytes.find(type);
  if (bytes == kBytes.end()) throw bad("ElementType", type, "an integer or real voxel type (MET_UCHAR, MET_SHORT, ...)");
  double need = bytes->second * static_cast<double>(channels);
  for (double d : dims) need *= d;
  const auto at = f.tellg();
  const double header_end = data_file == "LOCAL" ? (at < 0 ? 0.0 : static_cast<double>(at)) : 0.0;
  std::filesystem::path data = data_file == "LOCAL" ? file : std::filesystem::path(data_file);
  if (data.is_relative()) data = file.parent_path() / data;
  if (data_file != "LOCAL") check_data_size(file, "MetaImage", "a data file", 0, data_file, "ElementDataFile", 0);
  const double stored = static_cast<double>(std::filesystem::file_size(data)) - header_end;
  if (text) return;  // text voxels: their byte count says nothing (the reader checks them)
  if (!compressed) {
    if (header_size > 0) need += static_cast<double>(header_size);
    check_data_size(file, "MetaImage", "DimSize and " + type, need, data_file == "LOCAL" ? "" : data_file, "ElementDataFile",
                    static_cast<std::uintmax_t>(header_end));
    return;
  }
  // MetaIO allocates CompressedDataSize bytes and reads them: they must be there.
  if (compressed_size > stored)
    throw InputError(fmt::format("{}: MetaImage CompressedDataSize = {} but {} holds {:.0f} bytes of data", name, compressed_size,
                                 data.string(), stored));
  if (header_size != 0) throw bad("HeaderSize", std::to_string(header_size), "no HeaderSize with compressed data");
  const double have = inflated(data, header_end, need);
  if (have < need)
    throw InputError(fmt::format("{}: the MetaImage voxel data is cut short or damaged: DimSize and {} need {:.0f} bytes, the "
                                 "compressed data holds {:.0f}", name, type, need, have));
}

}  // namespace stentsim::segmentation
