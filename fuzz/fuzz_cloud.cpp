// Point-cloud scenes (io/cloud.h read_cloud: PCD ascii / binary /
// binary_compressed and PLY clouds), then what `recognize --cloud` does with
// an accepted cloud: the depth image, fitted or virtual intrinsics and the
// projection. The first byte picks the extension (pcd or ply) and the units.
#include "fuzz_util.h"
#include "io/cloud.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const bool ply = data[0] & 1;
  const pb::CloudUnits units = (data[0] >> 1) % 3 == 0   ? pb::CloudUnits::automatic
                               : (data[0] >> 1) % 3 == 1 ? pb::CloudUnits::millimetres
                                                         : pb::CloudUnits::metres;
  const std::string path = pbfuzz::write_file(ply ? "cloud.ply" : "cloud.pcd", data + 1, size - 1);
  pbfuzz::accept_or_reject([&] {
    const pb::PointCloudFile c = pb::read_cloud(path, units);
    if (c.organized()) {
      pb::organized_depth(c);
      pb::project_cloud(c, pb::fit_intrinsics(c, path));
    } else {
      pb::project_cloud(c, pb::virtual_camera(c, path, 64, 48));
    }
  });
  return 0;
}
