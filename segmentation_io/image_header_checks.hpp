#pragma once
// Label-image headers checked before VTK's readers see them. VTK 9.1's NIfTI,
// NRRD and MetaImage readers trust their headers: a damaged type, offset, size
// or field order crashes them or reads past the data, and a short file gives
// zeros with a warning at most. Each check refuses what the reader would
// misread, with an InputError naming the file and the field; the voxel data
// must be present in full (decompressed, for gzip).
#include <filesystem>

namespace stentsim::segmentation {

/// NIfTI-1 or -2, plain (.nii) or gzip (.nii.gz): sizeof_hdr and single-file
/// magic, an integer or real voxel type with its bitpix, 1 to 7 axes of at least
/// one voxel, finite pixdim, qform and sform, vox_offset past the header.
void check_nifti_header(const std::filesystem::path& file);

/// NRRD (.nrrd, .nhdr): `dimension: 3` before `sizes` (three positive counts, the
/// first at least 10: VTK takes a shorter first axis for vector components), a
/// known type, raw or gzip encoding, well-formed spacings, space directions and
/// origin, one detached `data file` at most (a regular file; no LIST or pattern).
void check_nrrd_header(const std::filesystem::path& file);

/// MetaImage (.mha, .mhd): uncompressed voxel data (after the .mha's header or in
/// the .mhd's ElementDataFile) against DimSize, ElementType and
/// ElementNumberOfChannels; the data file must be a regular file. Compressed data
/// and element types it does not know are left to the reader.
void check_metaimage_header(const std::filesystem::path& file);

}  // namespace stentsim::segmentation
