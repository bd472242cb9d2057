// A BOP scene folder (io/bop.h read_scene_json): the first byte picks the
// file the rest of the input becomes (0 scene_camera.json, 1 scene_gt.json,
// 2 scene_gt_info.json); the other two hold a valid one-image scene.
#include "fuzz_util.h"
#include "io/bop.h"

namespace {
const char* kFiles[3] = {"scene_camera.json", "scene_gt.json", "scene_gt_info.json"};
const char* kValid[3] = {
    R"({"0": {"cam_K": [500, 0, 320, 0, 500, 240, 0, 0, 1], "depth_scale": 1.0}})",
    R"({"0": [{"obj_id": 1, "cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": [0, 0, 1000]}]})",
    (R"({"0": [{"bbox_obj": [1, 2, 30, 40], "bbox_visib": [1, 2, 30, 40], "px_count_all": 900,)"
     R"( "px_count_valid": 800, "px_count_visib": 700, "visib_fract": 0.78}]})")};  // one string, two lines
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int which = data[0] % 3;
  for (int f = 0; f < 3; ++f)
    if (f == which)
      pbfuzz::write_file(std::string("scene/") + kFiles[f], data + 1, size - 1);
    else
      pbfuzz::write_file(std::string("scene/") + kFiles[f], kValid[f]);
  pbfuzz::accept_or_reject([&] { pb::read_scene_json(pbfuzz::work_dir() + "/scene"); });
  return 0;
}
