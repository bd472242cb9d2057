// The on-disk training cache: one file per model, descriptor and key.
// Layout: magic, version, key hash, payload size, payload FNV-1a, payload
// (key text, descriptor, the preprocessed views, the method's state).
// Written to a temporary file and renamed into place, so readers never see
// a partial file; anything unreadable is rebuilt, never misread.
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.h"
#include "core/file_lock.h"
#include "core/hash.h"
#include "recognition/model.h"
#include "recognition/registry.h"

namespace pb::cache {

namespace {

constexpr char kMagic[8] = {'P', 'B', 'T', 'R', 'A', 'I', 'N', '\0'};
// 2: standard FNV-1a keys over the view data and the method's own section;
// one binary format for every method. 3: the project's own normals (PCA in a
// radius on its kd-tree) replace PCL's in preprocessing: models trained by
// version 2 are retrained. 4: the project's own FPFH. 5: the project's own
// SHOT (descriptors equal to PCL's at rounding level). 6: the project's own
// BOARD frames (deterministic start axis of the hole search). 7: BOARD
// frames from their neighbours in kd-tree order (bbe454f changed the frames
// without this bump, so caches written before it kept the views' old frames
// under the same key: found when a new setting changed the key and moved
// seven bench-pipeline FPFH estimates).
constexpr uint32_t kVersion = 7;

std::string sanitize(const std::string& name) {
  std::string o;
  for (char c : name) o += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return o.empty() ? "model" : o.substr(0, 64);
}

void write_views(BinaryWriter& w, const std::vector<ViewData>& views) {
  w.pod<uint64_t>(views.size());
  for (const auto& v : views) {
    w.points(v.cloud.points);
    w.points(v.cloud.normals);
    w.vec(v.cloud.curvature);
    w.vec(v.cloud.pixel);
    w.pod<int32_t>(v.cloud.source_width);
    w.pod<int32_t>(v.cloud.source_height);
    w.pose(v.T_cam_model);
  }
}

std::vector<ViewData> read_views(BinaryReader& r) {
  const uint64_t nv = r.pod<uint64_t>();
  if (nv > 100000) r.fail("bad view count");
  std::vector<ViewData> views(nv);
  for (auto& v : views) {
    v.cloud.points = r.points();
    v.cloud.normals = r.points();
    v.cloud.curvature = r.vec<float>();
    v.cloud.pixel = r.vec<int>();
    v.cloud.source_width = r.pod<int32_t>();
    v.cloud.source_height = r.pod<int32_t>();
    const size_t n = v.cloud.points.size();
    if ((!v.cloud.normals.empty() && v.cloud.normals.size() != n) ||
        (!v.cloud.curvature.empty() && v.cloud.curvature.size() != n) ||
        (!v.cloud.pixel.empty() && v.cloud.pixel.size() != n))
      r.fail("inconsistent view arrays");
    v.T_cam_model = r.pose();
  }
  return views;
}

}  // namespace

Key training_key(const TrainingViews& views, const RecognitionSettings& s) {
  const nlohmann::ordered_json j = recognition_settings_json(s);
  const std::string section = descriptor_entry(s.descriptor).section;
  nlohmann::ordered_json k;
  k["cache_version"] = kVersion;
  k["descriptor"] = s.descriptor;
  k["preprocess"] = j["preprocess"];
  k[section] = j[section];
  if (section == "local") k["local"].erase("threads");  // results are identical for any thread count
  k["seed"] = s.seed;
  Key key;
  key.text = k.dump();
  Fnv1a64 f;
  f.field(key.text);
  f.value<uint64_t>(views.views.size());
  for (const auto& v : views.views) {
    f.value(v.cloud.width).value(v.cloud.height);
    f.bytes(v.cloud.points.data(), v.cloud.points.size() * sizeof(Vec3f));
    f.bytes(v.T_cam_model.R.data(), 9 * sizeof(double)).bytes(v.T_cam_model.t.data(), 3 * sizeof(double));
  }
  key.hash = f.digest();
  return key;
}

std::string file_name(const std::string& dir, const std::string& model_name, const std::string& descriptor,
                      const Key& key) {
  return dir + "/" + sanitize(model_name) + "-" + descriptor + "-" + hex16(key.hash) + ".bin";
}

// A fuzzing build (fuzz/, scripts/fuzz.sh) reads past the key and checksum
// comparisons, so mutated files reach the views and the methods' states.
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
constexpr bool kFuzzing = true;
#else
constexpr bool kFuzzing = false;
#endif

bool read(const std::string& path, const Key& key, TrainedModel& m) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    BinaryReader r(file, "training cache " + path);
    r.expect(kMagic, sizeof kMagic, "training cache");
    const uint32_t version = r.pod<uint32_t>();
    const uint64_t hash = r.pod<uint64_t>();
    if (version != kVersion || (!kFuzzing && hash != key.hash)) return false;
    const uint64_t size = r.pod<uint64_t>(), sum = r.pod<uint64_t>();
    if (size != file.size() - r.pos()) return false;
    if (!kFuzzing && Fnv1a64().bytes(file.data() + r.pos(), size).digest() != sum) return false;
    const std::string text = r.bytes(), descriptor = r.bytes();
    if (!kFuzzing && (text != key.text || descriptor != m.descriptor)) return false;
    std::vector<ViewData> views = read_views(r);
    std::unique_ptr<Method> method = make_method(m.settings);
    method->load(r);
    if (!r.at_end()) return false;  // a state of another version of the method
    m.views = std::move(views);
    m.method = std::move(method);
    return true;
  } catch (const std::exception&) {
    return false;  // corrupt or stale: rebuilt by the caller
  }
}

void write(const std::string& path, const Key& key, const TrainedModel& m) {
  BinaryWriter payload;
  payload.bytes(key.text);
  payload.bytes(m.descriptor);
  write_views(payload, m.views);
  m.method->save(payload);
  BinaryWriter head;
  head.raw(kMagic, sizeof kMagic);
  head.pod<uint32_t>(kVersion);
  head.pod<uint64_t>(key.hash);
  head.pod<uint64_t>(payload.buffer().size());
  head.pod<uint64_t>(Fnv1a64().bytes(payload.buffer().data(), payload.buffer().size()).digest());
  const std::string file = head.take() + payload.buffer();

  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  if (ec) throw InputError(path, "cache", "cannot create the cache directory: " + ec.message());
  const std::string tmp = unique_temp_path(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cache", "cannot write the training cache file");
    out.write(file.data(), static_cast<std::streamsize>(file.size()));
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw InputError(path, "cache", "cannot write the training cache file (disk full?)");
    }
  }
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cache", "cannot rename the training cache file into place: " + ec.message());
  }
}

}  // namespace pb::cache
