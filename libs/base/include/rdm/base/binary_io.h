// Little helpers for the daemon's binary files: append / read plain values and arrays.
// Readers never read past the end; a short or corrupt file reads as failed.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace rdm {

class BinaryWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  template <class T>
  void putArray(const std::vector<T>& v) {
    put(uint64_t(v.size()));
    out_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void putString(const std::string& s) {
    put(uint64_t(s.size()));
    out_.append(s);
  }
  std::string& bytes() { return out_; }

 private:
  std::string out_;
};

class BinaryReader {
 public:
  explicit BinaryReader(const std::string& bytes) : data_(bytes) {}
  template <class T>
  bool get(T& v) {
    if (data_.size() - pos_ < sizeof(T)) return ok_ = false;
    std::memcpy(&v, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  template <class T>
  bool getArray(std::vector<T>& v, uint64_t max_count) {
    uint64_t n = 0;
    if (!get(n) || n > max_count || (data_.size() - pos_) / sizeof(T) < n) return ok_ = false;
    v.resize(size_t(n));
    if (n > 0) std::memcpy(v.data(), data_.data() + pos_, size_t(n) * sizeof(T));
    pos_ += size_t(n) * sizeof(T);
    return true;
  }
  bool getString(std::string& s, uint64_t max_size) {
    std::vector<char> v;
    if (!getArray(v, max_size)) return false;
    s.assign(v.begin(), v.end());
    return true;
  }
  bool ok() const { return ok_; }
  bool atEnd() const { return pos_ == data_.size(); }

 private:
  const std::string& data_;
  size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace rdm
