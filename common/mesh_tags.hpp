#pragma once
// Tags every mesh artifact uses (artery.vtu, balloon.vtu): volume cells carry
// the cell array "Layer"; boundary faces are stored in the same VTU as 2D
// cells (quad/tri) carrying "FaceGroup" (and Layer = 0), so one file holds the
// body and its named surfaces and ParaView shows them with a Threshold.
namespace stentsim::tags {

inline constexpr const char* kLayer = "Layer";
inline constexpr const char* kFaceGroup = "FaceGroup";
/// Field of lumen.vtp (text "x y z", mm): the lesion a tree's region of
/// interest is centred on (segmentation); the placement treats the lesion there.
inline constexpr const char* kTreatedSite = "treated_site_point";

enum Layer : int { no_layer = 0, intima = 1, media = 2, adventitia = 3, balloon_wall = 4 };

enum FaceGroup : int {
  no_face = 0,
  endothelium = 1,
  outer_wall = 2,
  proximal_cut = 3,
  distal_cut = 4,
  balloon_inner = 5,
  balloon_outer = 6,
  balloon_end_proximal = 7,
  balloon_end_distal = 8,
};

inline const char* layer_name(int l) {
  switch (l) {
    case intima: return "intima";
    case media: return "media";
    case adventitia: return "adventitia";
    case balloon_wall: return "balloon";
    default: return "none";
  }
}

inline const char* face_group_name(int f) {
  switch (f) {
    case endothelium: return "endothelium";
    case outer_wall: return "outer_wall";
    case proximal_cut: return "proximal_cut";
    case distal_cut: return "distal_cut";
    case balloon_inner: return "balloon_inner";
    case balloon_outer: return "balloon_outer";
    case balloon_end_proximal: return "balloon_end_proximal";
    case balloon_end_distal: return "balloon_end_distal";
    default: return "none";
  }
}

}  // namespace stentsim::tags
