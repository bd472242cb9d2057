// The project's one binary reader/writer (training cache files and the
// trained state of every method). Host byte order: cache files are
// machine-local and rebuilt when unreadable. Every read is bounds-checked:
// a truncated or corrupt buffer throws BinaryError, never reads past the end.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/types.h"

namespace pb {

struct BinaryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class BinaryWriter {
 public:
  template <typename T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    buf_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void raw(const void* data, size_t n) { buf_.append(static_cast<const char*>(data), n); }
  void bytes(const std::string& s) {  // length-prefixed
    pod<uint64_t>(s.size());
    buf_ += s;
  }
  template <typename T>
  void vec(const std::vector<T>& v) {  // length-prefixed array of trivially copyable values
    static_assert(std::is_trivially_copyable_v<T>);
    pod<uint64_t>(v.size());
    if (!v.empty()) raw(v.data(), v.size() * sizeof(T));
  }
  void points(const std::vector<Vec3f>& p);  // as a float array of 3 x n
  void pose(const Pose& T);                  // R row-major then t, doubles
  const std::string& buffer() const { return buf_; }
  std::string take() { return std::move(buf_); }

 private:
  std::string buf_;
};

class BinaryReader {
 public:
  // `what` names the data in error messages ("training cache", "ppf state").
  BinaryReader(const std::string& buf, std::string what, size_t pos = 0)
      : buf_(buf), what_(std::move(what)), pos_(pos) {}
  template <typename T>
  T pod() {
    static_assert(std::is_trivially_copyable_v<T>);
    need(sizeof(T));
    T v;
    std::memcpy(&v, buf_.data() + pos_, sizeof v);
    pos_ += sizeof v;
    return v;
  }
  std::string bytes();
  template <typename T>
  std::vector<T> vec() {
    const uint64_t n = pod<uint64_t>();
    if (n > (buf_.size() - pos_) / sizeof(T)) fail("array longer than the data");
    std::vector<T> v(n);
    if (n) std::memcpy(static_cast<void*>(v.data()), buf_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
    return v;
  }
  std::vector<Vec3f> points();
  Pose pose();
  // Reads sizeof(magic) bytes and fails unless they equal `magic`.
  void expect(const char* magic, size_t n, const std::string& what);
  void need(size_t n) const {
    if (n > buf_.size() - pos_) fail("truncated");
  }
  size_t pos() const { return pos_; }
  bool at_end() const { return pos_ == buf_.size(); }
  [[noreturn]] void fail(const std::string& why) const { throw BinaryError(what_ + ": " + why); }

 private:
  const std::string& buf_;
  std::string what_;
  size_t pos_;
};

}  // namespace pb
