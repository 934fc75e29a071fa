// Output appears whole or not at all, never destroys a file quadgen did not write, and never
// replaces one of the run's own inputs.
//
// OutputDirectory (derive, fit, diagnose, predict --out DIR): every file is written into a private
// staging directory beside DIR and the set is switched in by one rename (an atomic exchange
// when DIR already holds an earlier run). DIR is replaced only if it is new, empty, or holds
// exactly what an earlier run of the same command wrote (listed in its manifest, kManifestName,
// each file unchanged since); a kill at any moment leaves either the earlier run or the new
// one, and two runs into one DIR leave one of them whole.
//
// OutputFiles (simulate --out TRAJ.csv, with TRAJ.svg beside it): files among other files.
// An existing file is replaced only if the record beside it (.quadgen-files) says the same
// command wrote it and it is unchanged since. Each file is renamed into place from the staging
// directory; a companion of the previous run is removed first, so a kill leaves a missing
// plot, never a plot of another run.
#pragma once
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <filesystem>
#include <vector>

namespace quadgen::output {

struct OutputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Lists the files of one run with their sizes and FNV-1a hashes, so that a later run (and a
// test) can tell a complete quadgen output directory from anything else.
inline constexpr const char* kManifestName = ".quadgen-manifest";

class StagingDirectory;

// The folders an output set had to create to hold its staging directory: removed again
// (those left empty, deepest first) when the set is never committed, so that a run that
// fails (a bad vehicle file, a flight that cannot be fitted) leaves nothing behind.
class CreatedFolders {
 public:
  void create(const std::filesystem::path& folder);  // like create_directories, remembering what it made
  void keep();
  ~CreatedFolders();

 private:
  std::vector<std::filesystem::path> created_;  // outermost first
  std::vector<int> slots_;                      // where the interrupt handler finds them
};

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the staging directories, the
// files staged in them and the folders created for them before the process dies of the signal, so that Ctrl-C
// during a long diagnosis leaves nothing behind (SIGKILL cannot be caught: the next run into
// the same place removes what it leaves). For the command-line program's main.
void remove_empty_outputs_on_interrupt();

class OutputDirectory {
 public:
  // Checks at once (before any long work) that `dir` may be written: not one of `inputs`, no
  // input inside it, not the working directory or above it, and replaceable (see above).
  // `command` (derive, fit, ...) is recorded in the manifest: a directory one command wrote is
  // not replaced by another (a derive into a diagnosis's folder would throw the diagnosis away).
  OutputDirectory(const std::string& dir, const std::string& command, const std::vector<std::string>& inputs);
  ~OutputDirectory();  // a set never committed leaves nothing behind
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  // Writes one file of the set (a plain file name) into the staging directory.
  void add(const std::string& filename, const std::string& content);
  // Switches the whole set in.
  void commit();
  const std::string& dir() const { return dir_; }
  // After commit: whether an earlier run of the same command was replaced and removed (the
  // command line says so: two runs given one --out keep only the second). An earlier run
  // kept aside, because files appeared in it meanwhile, is said where it is kept instead.
  bool replaced_earlier_run() const { return replaced_; }

 private:
  std::string dir_;
  std::string command_;
  bool replaced_ = false;
  std::vector<std::string> inputs_;
  CreatedFolders created_;  // destroyed after the staging directory inside them
  std::unique_ptr<StagingDirectory> staging_;
  std::vector<std::pair<std::string, std::string>> manifest_;  // file name, "hash size"
};

class OutputFiles {
 public:
  // `paths`: what this run writes, in one folder; distinct, none an input, none a directory.
  // A file already at a path is replaced only if `command` wrote it there and it is unchanged
  // since (a record beside the files, .quadgen-files, lists what each run wrote).
  OutputFiles(const std::vector<std::string>& paths, const std::string& command, const std::vector<std::string>& inputs);
  ~OutputFiles();
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;

  // Content of paths[i]; a path never set is not written, and a previous file there is removed.
  void set(size_t i, const std::string& content);
  void commit();
  // Whether the commit replaced files an earlier run of the command wrote at these paths, and
  // which, as the caller named them (a review: the note named the trajectory, by its absolute
  // path, where only the earlier plot had been left).
  bool replaced_earlier_run() const { return !replaced_.empty(); }
  const std::vector<std::string>& replaced_files() const { return replaced_; }

 private:
  void update_record();
  std::map<std::string, std::string> still_pending(const std::filesystem::path& parent) const;
  std::vector<std::string> replaced_;
  std::string command_;
  std::vector<std::string> paths_;
  std::vector<std::string> named_;  // paths_ as the caller gave them
  std::vector<bool> written_;
  CreatedFolders created_;  // destroyed after the staging directory inside them
  std::unique_ptr<StagingDirectory> staging_;
};

// True if `filename` holds what a complete quadgen run wrote into `dir` according to its
// manifest (every listed file present with its size and hash, nothing else). For tests and
// for users checking an output directory.
bool complete_output_directory(const std::string& dir, std::string* why = nullptr);

namespace detail {
// Moves an earlier run's folder `staged` that still holds files quadgen did not write to a
// visible name beside `target` ("<target>.previous-<pid>", or "quadgen-previous-<pid>" where
// that name would be too long), marked so that no later run removes it; returns where it is
// (`staged` itself if no rename succeeded). Declared here for its test.
std::filesystem::path keep_aside(const std::filesystem::path& staged, const std::filesystem::path& target);
// The start of a target's staging folders' names, ".<target>.quadgen-tmp." (a long name cut
// and told apart by a hash), and the pid in such a folder's full name "<stem><pid>.XXXXXX"
// (-1 for any other name: only folders named so are ever removed as stale). For their test.
std::string staging_stem(const std::string& target_name);
long staging_pid(const std::string& name, const std::string& stem);
}  // namespace detail

}  // namespace quadgen::output
