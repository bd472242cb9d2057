#include "io/folder.h"

#include "core/error.h"

namespace pb {

namespace fs = std::filesystem;

namespace {

// Moves the finished `tmp` to `out`, replacing a previous `out`.
void move_into_place(const fs::path& tmp, const fs::path& out) {
  std::error_code ec;
  if (fs::exists(out)) {
    const fs::path old = out.string() + ".old";
    fs::remove_all(old, ec);
    fs::rename(out, old);
    fs::rename(tmp, out);
    fs::remove_all(old, ec);
  } else {
    if (out.has_parent_path()) fs::create_directories(out.parent_path());
    fs::rename(tmp, out);
  }
}

}  // namespace

void write_folder_atomically(const std::string& out, const std::string& error_prefix,
                             const std::function<void(const fs::path& tmp)>& fill) {
  const fs::path dir(out);
  const fs::path tmp = dir.string() + ".partial";
  std::error_code ec;
  fs::remove_all(tmp, ec);
  try {
    fs::create_directories(tmp);
    fill(tmp);
    move_into_place(tmp, dir);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(tmp, ec);
    throw InputError(out, "--out", error_prefix + e.what());
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace pb
