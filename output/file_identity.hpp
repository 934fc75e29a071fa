// Which file a path names, as the kernel resolves it (links followed): the device and inode.
// Two paths name one file when these agree, whatever their spelling (a hard or symbolic link,
// "a/../b"). One home for the checks that a log is not named twice and that an output does
// not land on an input.
#pragma once
#include <sys/stat.h>

#include <optional>
#include <string>

namespace quadgen::output {

struct FileId {
  dev_t dev;
  ino_t ino;
  bool operator<(const FileId& o) const { return dev != o.dev ? dev < o.dev : ino < o.ino; }
};

// Nothing where the path names no file (yet).
inline std::optional<FileId> file_id(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::nullopt;
  return FileId{st.st_dev, st.st_ino};
}

}  // namespace quadgen::output
