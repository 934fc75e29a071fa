#include "runtime/log_file.hpp"

#include "output/file_identity.hpp"

#include <algorithm>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <utility>

#include "runtime/flight_log.hpp"

namespace quadgen::runtime {

namespace {

const char* file_kind(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

// What a file above its limit is told: a log's limit can be raised, a YAML file's is its kind's.
std::string above_the_limit(unsigned long long limit, bool of_its_kind) {
  return "above the limit of " + std::to_string(limit) +
         (of_its_kind ? " bytes for this kind of file (a few kilobytes is usual)"
                      : " bytes (set QUADGEN_MAX_INPUT_BYTES to raise it)");
}

}  // namespace

LogFile::LogFile(const std::string& path, const std::string& expected, unsigned long long limit)
    : path_(path), expected_(expected), given_limit_(limit) {
  // ": cannot open a vehicle file" read as a fault of quadgen's (a review, helper-135).
  if (path.empty()) throw LogError("an empty path where " + expected + " was expected (an unset shell variable?)");
  fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw LogError(path + ": cannot open " + expected + ": " + std::strerror(errno));
  try {
    struct stat st {};
    if (::fstat(fd_, &st) != 0) throw LogError(path + ": cannot stat " + expected + ": " + std::strerror(errno));
    if (!S_ISREG(st.st_mode))
      throw LogError(path + ": " + file_kind(st.st_mode) + ", not a regular file (expected " + expected + ")");
    size_ = static_cast<unsigned long long>(st.st_size);
    limit_ = limit ? std::min(limit, max_input_bytes()) : max_input_bytes();  // the variable may lower a kind's
    if (size_ > limit_)
      throw LogError(path + ": " + std::to_string(size_) + " bytes, " + above_the_limit(limit_, limit_ == limit));
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

LogFile::~LogFile() { ::close(fd_); }

void refuse_repeated_files(const std::vector<std::string>& paths, const std::string& what) {
  std::map<output::FileId, const std::string*> seen;
  for (const auto& p : paths) {
    const auto id = output::file_id(p);
    if (!id) continue;
    const auto [at, inserted] = seen.emplace(*id, &p);
    if (!inserted)
      throw LogError(p + ": the same file as " + *at->second +
                     (p == *at->second ? " (named twice)" : " (a link to it, or it to this)") + ": give each " + what +
                     " once");
  }
}

std::string read_head(const std::string& path, std::size_t n) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return {};
  struct stat st {};
  std::string head(n, '\0');
  ssize_t got = 0;
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) got = ::read(fd, head.data(), n);
  ::close(fd);
  head.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
  return head;
}

std::string LogFile::read_all() const {
  std::string bytes;
  bytes.reserve(size_);
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd_, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw LogError(path_ + ": cannot read " + expected_ + ": " + std::strerror(errno));
    if (n == 0) return bytes;
    bytes.append(buf, static_cast<std::size_t>(n));
    if (bytes.size() > limit_)  // it grew while being read
      throw LogError(path_ + ": it grew while read, " + above_the_limit(limit_, limit_ == given_limit_));
  }
}

void LogFile::set_blocking() const { ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_NONBLOCK); }

}  // namespace quadgen::runtime
