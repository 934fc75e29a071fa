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

// Largest vehicle file, column mapping or fitted-parameter file, in bytes: yaml-cpp builds
// about 270 bytes of nodes for a byte of a flow list (a hostile-input audit, helper-161: a 5 MB
// vehicle file took 1.3 GB), and the largest such file quadgen writes is a few kilobytes.
constexpr unsigned long long kMaxYamlBytes = 1ULL << 20;

class LogFile {
 public:
  // `limit`: the most bytes accepted; 0 for max_input_bytes() (a log's), which also lowers a
  // smaller one. A YAML file's is kMaxYamlBytes: its parser holds a few hundred bytes a byte.
  LogFile(const std::string& path, const std::string& expected, unsigned long long limit = 0);
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
  std::string path_, expected_;
  int fd_ = -1;
  unsigned long long size_ = 0, limit_ = 0, given_limit_ = 0;
};

// Refuses a file named twice among `paths`, by its name or by what it is (a hard or symbolic
// link to one named before): one flight counted twice doubles its weight in a fit, and a joint
// diagnosis would compare it with itself. A path that cannot be looked at is left to its
// reader, which says why. Throws LogError naming both paths.
void refuse_repeated_files(const std::vector<std::string>& paths, const std::string& what);

}  // namespace quadgen::runtime
