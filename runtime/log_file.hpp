// A log file opened for reading, the one way every log reader opens its input: without
// blocking (a FIFO is refused at once, not waited on), checked on what was opened (fstat, not a
// second look-up of the path), a regular file of at most max_input_bytes(). Errors are
// LogError with the path and what was expected ("a CSV log", "a ULog file").
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace quadgen::runtime {

// The first `n` bytes of a regular file, for recognising a format by its magic bytes; fewer
// (possibly none) when it is shorter, cannot be opened or is no regular file. Opened without
// blocking, so that a FIFO is not waited on.
std::string read_head(const std::string& path, std::size_t n);

class LogFile {
 public:
  LogFile(const std::string& path, const std::string& expected);
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;

  int fd() const { return fd_; }
  unsigned long long size() const { return size_; }    // bytes when opened
  unsigned long long limit() const { return limit_; }  // max_input_bytes()
  // The whole file, at most limit() bytes even if it grows while being read.
  std::string read_all() const;
  // Reads may block from here on (a regular file's reads do not wait for writers anyway).
  void set_blocking() const;

 private:
  std::string path_;
  int fd_ = -1;
  unsigned long long size_ = 0, limit_ = 0;
};

// Refuses a file named twice among `paths`, by its name or by what it is (a hard or symbolic
// link to one named before): one flight counted twice doubles its weight in a fit, and a joint
// diagnosis would compare it with itself. A path that cannot be looked at is left to its
// reader, which says why. Throws LogError naming both paths.
void refuse_repeated_files(const std::vector<std::string>& paths, const std::string& what);

}  // namespace quadgen::runtime
