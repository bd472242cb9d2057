#include "report/gallery.h"

#include <algorithm>
#include <memory>

#include "core/error.h"
#include "io/bop.h"
#include "io/png.h"
#include "report/overlay.h"

namespace pb {

namespace {

double translation_error(const TrialRecord* r) { return r->errors ? r->errors->translation_mm : 0.0; }

}  // namespace

std::map<std::string, std::vector<GalleryItem>> select_gallery(const std::vector<TrialRecord>& records,
                                                               const GalleryOptions& opt) {
  std::map<std::string, std::vector<const TrialRecord*>> by_method;
  for (const auto& r : records) by_method[r.descriptor + "+" + r.refinement].push_back(&r);
  std::map<std::string, std::vector<GalleryItem>> out;
  for (auto& [method, recs] : by_method) {
    std::sort(recs.begin(), recs.end(), [](const TrialRecord* a, const TrialRecord* b) { return a->key < b->key; });
    std::vector<const TrialRecord*> posed_fail, unposed_fail, ok;
    for (const auto* r : recs) {
      if (r->correct.value_or(false))
        ok.push_back(r);
      else if (r->estimate)
        posed_fail.push_back(r);
      else
        unposed_fail.push_back(r);
    }
    const auto worst_first = [](const TrialRecord* a, const TrialRecord* b) {
      return translation_error(a) > translation_error(b);
    };
    std::stable_sort(posed_fail.begin(), posed_fail.end(), worst_first);
    std::stable_sort(ok.begin(), ok.end(), worst_first);
    posed_fail.insert(posed_fail.end(), unposed_fail.begin(), unposed_fail.end());
    auto& items = out[method];
    for (size_t i = 0; i < posed_fail.size() && static_cast<int>(i) < opt.failures; ++i)
      items.push_back(GalleryItem{posed_fail[i], false, "", ""});
    for (size_t i = 0; i < ok.size() && static_cast<int>(i) < opt.successes; ++i)
      items.push_back(GalleryItem{ok[i], true, "", ""});
  }
  return out;
}

void draw_gallery(std::map<std::string, std::vector<GalleryItem>>& gallery) {
  std::map<std::string, std::unique_ptr<BopDataset>> datasets;
  std::map<std::string, Mesh> meshes;
  for (auto& [method, items] : gallery)
    for (GalleryItem& it : items) {
      const TrialRecord& r = *it.record;
      try {
        auto& ds = datasets[r.dataset];
        if (!ds) ds = std::make_unique<BopDataset>(r.dataset);
        const int obj = r.obj_id.value_or(0);
        const std::string mkey = r.dataset + "#" + std::to_string(obj);
        if (!meshes.count(mkey)) meshes[mkey] = ds->load_model(obj);
        const SceneInfo sc = ds->load_scene(r.split, r.scene_id);
        const auto im = sc.images.find(r.im_id);
        if (im == sc.images.end()) throw InputError(r.dataset, "image", "no image " + std::to_string(r.im_id));
        const DepthImage depth = ds->load_depth(r.split, r.scene_id, im->second);
        Intrinsics K = im->second.K;
        K.width = depth.width;
        K.height = depth.height;
        const Pose est = r.estimate ? r.estimate->pose() : Pose{};
        const Pose gt = r.gt ? r.gt->pose() : Pose{};
        const RgbImage img = depth_overlay(depth, K, meshes[mkey], r.estimate ? &est : nullptr, r.gt ? &gt : nullptr);
        it.png = encode_rgb8_png(img.width, img.height, img.rgb);
      } catch (const InputError& e) {
        it.note = std::string("no image: ") + e.what();
      }
    }
}

}  // namespace pb
