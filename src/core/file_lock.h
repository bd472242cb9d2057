// Advisory whole-file locks (flock) and unique temporary names, for several
// processes sharing one results folder, scene folder or training cache (the
// shards of a sweep, possibly on several hosts of one shared file system).
// A lock is released when its holder exits, killed or not. PCL-free.
#pragma once

#include <string>

namespace pb {

class FileLock {
 public:
  // Blocks until PATH (created if missing) is locked exclusively.
  static FileLock acquire(const std::string& path);
  // Locks PATH exclusively if no other process holds it; otherwise returns
  // a lock with held() == false. Throws InputError if PATH cannot be opened.
  static FileLock try_acquire(const std::string& path);

  FileLock() = default;  // holds nothing
  FileLock(FileLock&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
  FileLock& operator=(FileLock&& other) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

  bool held() const { return fd_ >= 0; }

 private:
  explicit FileLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

// PATH + ".tmp.<host>.<pid>.<n>": a name no other process or thread, on this
// host or another sharing the file system, uses at the same time; write
// there, then rename onto PATH.
std::string unique_temp_path(const std::string& path);

}  // namespace pb
