// Output files appear whole or not at all: each file is written to a temporary beside
// its target and renamed into place only after every file of the job was written.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace quadgen {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class OutputSet {
 public:
  explicit OutputSet(std::string dir);
  ~OutputSet();  // removes temporaries if commit() was not reached
  void add(const std::string& filename, const std::string& content);
  void commit();  // rename all temporaries into place

 private:
  std::string dir_;
  std::vector<std::pair<std::string, std::string>> pending_;  // temp path, final path
  bool committed_ = false;
};

}  // namespace quadgen
