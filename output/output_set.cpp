#include "output/output_set.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "output/file_identity.hpp"
#include "output/fnv1a.hpp"
#include "output/joined.hpp"
#include "output/sinks.hpp"

namespace quadgen::output {
namespace fs = std::filesystem;

namespace {

constexpr const char* kManifestHeader = "quadgen output set 2";
// Manifests written until 2026-11-28: their hashes are FNV-1a under the offset basis with a
// digit dropped (output/fnv1a.hpp), recognised under this header only.
constexpr const char* kManifestHeaderOldBasis = "quadgen output set 1";
const std::string kStagingInfix = ".quadgen-tmp.";
constexpr const char* kCommandKey = "command ";
// Put into an earlier run's folder that is kept because it holds files quadgen did not write:
// no later run removes a folder holding it as a stale staging directory.
constexpr const char* kKeepMarker = ".quadgen-keep";
// Beside the files OutputFiles writes (simulate's trajectory and plot): what it wrote there.
constexpr const char* kFilesRecordName = ".quadgen-files";
// The record of a commit under way: this run's files with their new hashes, in place before
// the first file is moved and removed after the record is. A run killed between the moves
// (SIGKILL, a power cut) leaves each file either as the record or as this says, and the next
// run takes either as this command's (a red-team review: a simulate killed there left its
// files beside the earlier record, and every later run to that path was refused).
constexpr const char* kPendingRecordName = ".quadgen-files-pending";

[[noreturn]] void fail(const fs::path& p, const std::string& what) {
  throw OutputError(printable(p.string()) + ": " + what);
}

std::string errno_text() { return std::strerror(errno); }

// The process's umask, read without changing it (/proc/self/status, Linux 4.7 and later:
// umask() itself sets it, which another thread could see); 022, the common default, where
// that file cannot say.
mode_t current_umask() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("Umask:", 0) == 0) return static_cast<mode_t>(std::strtol(line.c_str() + 6, nullptr, 8) & 0777);
  return 022;
}

// The mode an output folder gets as it moves into place: that of the folder it replaces,
// else what mkdir would give it (0777 less the umask). Staging folders are made private by
// mkdtemp (0700), which kept every output folder from others who could read its parent.
// The set-group-ID bit a folder inherits in a shared group's folder is kept. A best effort:
// some file systems (vfat, some network mounts) refuse chmod, and the output is no less
// complete for it.
void set_published_mode(const fs::path& staged, const fs::path& target) {
  struct stat st {};
  mode_t mode = 0777 & ~current_umask();
  if (::stat(target.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) mode = st.st_mode & 07777;
  if (::stat(staged.c_str(), &st) == 0) mode |= st.st_mode & S_ISGID;
  (void)::chmod(staged.c_str(), mode);
}

void fsync_path(const fs::path& p, int flags) {
  const int fd = ::open(p.c_str(), flags | O_CLOEXEC);
  if (fd < 0) fail(p, "cannot open to sync: " + errno_text());
  const int rc = ::fsync(fd);
  ::close(fd);
  if (rc != 0) fail(p, "cannot sync to disk: " + errno_text());
}

// The absolute form of a path named on the command line: symbolic links in its existing part
// followed before a '..' after them is applied, as the file system does (so that `link/../x`
// is x beside the link's target, not beside the link); the part that does not exist yet taken
// as written, normalised; no trailing '/' (`new/.` is `new`). A '..' after a link that leads
// nowhere is applied as written (`dangling/..` is the link's folder, where the kernel finds no
// path): such a folder holds the link, which no run replaces.
fs::path resolved(const std::string& name) {
  if (name.empty()) throw OutputError("an output path is empty");
  std::error_code ec;
  const fs::path p = fs::absolute(fs::path(name), ec);
  fs::path r = fs::weakly_canonical(p, ec);
  if (ec) r = p.lexically_normal();
  while (!r.has_filename() && r.has_relative_path()) r = r.parent_path();
  return r;
}

// A file path named on the command line: its folder resolved, the file itself not (so that a
// symbolic link there is replaced, never the file it points to).
fs::path resolved_file(const std::string& name) {
  if (name.empty()) throw OutputError("an output path is empty");
  std::error_code ec;
  const fs::path p = fs::absolute(fs::path(name), ec);
  if (!p.has_filename() || p.filename() == "." || p.filename() == "..") fail(p, "names a directory; expected a file name");
  const fs::path parent = fs::weakly_canonical(p.parent_path(), ec);
  return (ec ? p.parent_path().lexically_normal() : parent) / p.filename();
}

// A name longer than a file system takes (NAME_MAX, 255 bytes on Linux's) failed only at the
// end, when the finished output was moved into place: refused before the work instead.
void check_name_lengths(const fs::path& p) {
  for (const auto& part : p)
    if (part.string().size() > NAME_MAX)
      fail(p, "has a name of " + std::to_string(part.string().size()) + " bytes, longer than the " +
                  std::to_string(NAME_MAX) + " a file system takes; choose a shorter one");
}

bool inside(const fs::path& child, const fs::path& parent) {
  const auto c = child.lexically_normal(), pa = parent.lexically_normal();
  auto ci = c.begin();
  for (auto pi = pa.begin(); pi != pa.end(); ++pi, ++ci)
    if (ci == c.end() || *ci != *pi) return false;
  return true;
}

std::map<FileId, std::string> identities(const std::vector<std::string>& paths) {
  std::map<FileId, std::string> ids;
  for (const auto& p : paths)
    if (const auto id = file_id(p)) ids[*id] = p;
  return ids;
}

// A name an output set may hold: a plain file name, never a path. A manifest is read from disk
// and may have been edited: a name with '/' or ".." in it would send the removal of the
// earlier run's files anywhere. A manifest line is "hash size name": a name with a line break
// in it would forge a line of its own, one with blanks at its ends would not read back as itself.
bool plain_file_name(const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos ||
      name.rfind(".quadgen", 0) == 0 || name.front() == ' ' || name.back() == ' ')
    return false;
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

void check_file_name(const std::string& name) {
  if (!plain_file_name(name)) throw OutputError("internal: '" + printable(name) + "' is not a plain output file name");
}

// What a manifest says: the command that wrote it, and file name -> "hash size". Manifests
// written before the command was recorded name none; it is inferred from their files.
struct Manifest {
  bool present = false;
  std::string command;
  std::map<std::string, std::string> files;
  std::vector<std::string> bad_lines;  // names that are not plain file names, lines that are not "hash size name"
  bool old_basis = false;              // written under kManifestHeaderOldBasis
};

std::string command_from_files(const std::map<std::string, std::string>& files) {
  for (const auto& [file, command] : std::map<std::string, std::string>{
           {"diagnosis.json", "diagnose"}, {"fit.json", "fit"}, {"prediction.json", "predict"}, {"model.hpp", "derive"}})
    if (files.count(file)) return command;
  return "";
}

// A hash as the manifest writes it: 16 lower-case hex digits.
bool hash_text(const std::string& s) {
  return s.size() == 16 && s.find_first_not_of("0123456789abcdef") == std::string::npos;
}

// A manifest is input like any other: a FIFO would block, /dev/zero never end. Only a regular
// file (not a link) of at most 1 MiB is read; anything else is a manifest quadgen did not write.
Manifest read_manifest_file(const fs::path& file) {
  Manifest m;
  struct stat st {};
  if (::lstat(file.c_str(), &st) != 0) return m;
  m.present = true;
  if (!S_ISREG(st.st_mode) || st.st_size > (1 << 20)) {
    m.bad_lines.push_back("(not a regular file of at most 1 MiB)");
    return m;
  }
  std::ifstream in(file, std::ios::binary);
  std::string line;
  const auto next = [&] {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next() || (line != kManifestHeader && line != kManifestHeaderOldBasis)) {
    m.bad_lines.push_back(line);
    return m;
  }
  m.old_basis = line == kManifestHeaderOldBasis;
  while (next()) {
    if (line.empty()) continue;
    if (line.rfind(kCommandKey, 0) == 0) {
      m.command = line.substr(std::strlen(kCommandKey));
      continue;
    }
    std::istringstream ls(line);
    std::string hash, size, name;
    if (ls >> hash >> size && std::getline(ls >> std::ws, name) && plain_file_name(name) && hash_text(hash) &&
        size.find_first_not_of("0123456789") == std::string::npos)
      m.files[name] = hash + " " + size;
    else m.bad_lines.push_back(line);
  }
  if (m.command.empty()) m.command = command_from_files(m.files);
  return m;
}

// The record beside simulate's files, read as the manifest is; a record with any line quadgen
// would not write (an edited one) vouches for nothing.
Manifest read_files_record(const fs::path& file) {
  Manifest m = read_manifest_file(file);
  if (!m.bad_lines.empty()) {
    m.files.clear();
    m.command.clear();
  }
  return m;
}

Manifest read_manifest(const fs::path& dir) { return read_manifest_file(dir / kManifestName); }

std::string manifest_text(const std::string& command, const std::map<std::string, std::string>& files) {
  std::string text = std::string(kManifestHeader) + "\n" + kCommandKey + command + "\n";
  for (const auto& [name, hash_size] : files) {
    check_file_name(name);
    text += hash_size + " " + name + "\n";
  }
  return text;
}

// "hash size" of a file as the manifest records it, read in pieces; "" for anything but a
// regular file (a symbolic link is never quadgen's: it wrote none).
std::string hash_and_size(const fs::path& p, uint64_t basis = kFnv1aOffsetBasis) {
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return "";
  std::ifstream in(p, std::ios::binary);
  Fnv1a h(basis);
  unsigned long long size = 0;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    const auto n = static_cast<size_t>(in.gcount());
    h.add(buf.data(), n);
    size += n;
  }
  return h.hex() + " " + std::to_string(size);
}

// Whether a file is what a manifest line recorded, hashed as that manifest hashes.
bool unchanged_since(const fs::path& p, const std::string& recorded, const Manifest& m) {
  return recorded == hash_and_size(p, m.old_basis ? kFnv1aLegacyBasis : kFnv1aOffsetBasis);
}

std::string first_names(const std::vector<std::string>& names) {
  const std::vector<std::string> first(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(std::min<size_t>(3, names.size())));
  const std::string out = joined(first, ", ", [](const std::string& n) { return printable(n); });
  return names.size() > 3 ? out + ", ..." : out;
}

// A symbolic link on the way to an output that cannot be followed: the path itself, or the
// nearest part of it that exists (`--out dangling/sub`). The finished output could not move
// onto it ("Not a directory" once the work was done), nor could the folders below it be made
// ("File exists"); quadgen does not make the folders a link points to. Refused before the work.
void refuse_links_that_lead_nowhere(const fs::path& target) {
  std::error_code ec;
  fs::path p = target;
  while (!fs::exists(fs::symlink_status(p, ec)) && p.has_relative_path()) p = p.parent_path();
  if (!fs::is_symlink(fs::symlink_status(p, ec))) return;
  const fs::file_status followed = fs::status(p, ec);
  if (fs::exists(followed)) return;
  std::error_code read_ec;
  const fs::path to = fs::read_symlink(p, read_ec);
  const std::string where = read_ec ? "" : " to " + printable((to.is_absolute() ? to : p.parent_path() / to).lexically_normal().string());
  if (ec == std::errc::too_many_symbolic_link_levels)
    fail(p, "is a symbolic link that loops (it leads back to itself through links); choose another output path");
  if (followed.type() == fs::file_type::not_found)
    fail(p, "is a symbolic link" + where + ", which leads nowhere (it does not exist); create that directory or choose "
            "another output path");
  fail(p, "is a symbolic link" + where + " that cannot be followed (" + ec.message() + "); choose another output path");
}

// Refuses to replace a directory unless it holds exactly what an earlier run of the same
// command wrote: every file listed in its manifest and unchanged since (size and hash), a
// manifest that names only plain files, and nothing else.
void check_replaceable(const fs::path& dir, const std::string& command) {
  std::error_code ec;
  if (!fs::exists(dir, ec)) return;
  if (!fs::is_directory(dir, ec)) fail(dir, "exists and is not a directory");
  const Manifest m = read_manifest(dir);
  if (!m.bad_lines.empty())
    fail(dir, "its " + std::string(kManifestName) + " is not one quadgen writes (at '" + printable(m.bad_lines.front()) +
                  "'; a manifest is a small file naming plain files only); remove the directory or choose another --out");
  if (!m.command.empty() && m.command != command)
    fail(dir, "holds the output of 'quadgen " + printable(m.command) + "', which 'quadgen " + command +
                  "' does not replace; choose another --out directory or remove it");
  std::vector<std::string> foreign, changed;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name == kManifestName) continue;
    const auto it = m.files.find(name);
    if (it == m.files.end() || !fs::is_regular_file(e.symlink_status())) foreign.push_back(name);
    else if (!unchanged_since(e.path(), it->second, m)) changed.push_back(name);
  }
  if (ec) fail(dir, "cannot list the directory: " + ec.message());
  if (!foreign.empty())
    fail(dir, "holds files quadgen did not write (" + first_names(foreign) + "); choose a new --out directory or remove them");
  if (!changed.empty())
    fail(dir, "holds files changed since quadgen wrote them (" + first_names(changed) +
                  "); choose a new --out directory or move them away");
}

// Files `inputs` names that `dir` is or contains, by path and by file identity (hard links).
void check_not_input(const fs::path& target, const std::vector<std::string>& inputs) {
  std::error_code ec;
  for (const auto& in : inputs) {
    if (in.empty() || !fs::exists(in, ec)) continue;
    const fs::path p = fs::canonical(in, ec);
    if (!ec && inside(p, target)) fail(target, "is or contains the input " + printable(in) + "; write the output elsewhere");
  }
  if (!fs::is_directory(target, ec)) return;
  const auto ids = identities(inputs);
  for (const auto& e : fs::directory_iterator(target, ec))
    if (const auto id = file_id(e.path().string()); id && ids.count(*id))
      fail(target, "holds the input " + printable(ids.at(*id)) + " (a link to it); write the output elsewhere");
}

void check_not_above_working_directory(const fs::path& target) {
  std::error_code ec;
  const fs::path cwd = fs::canonical(fs::current_path(ec), ec);
  if (target == target.root_path() || (!ec && inside(cwd, target)))
    fail(target, "is the working directory or above it; name a directory of its own for the output");
}

bool process_alive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

void remove_tree_quietly(const fs::path& p) {
  std::error_code ec;
  fs::remove_all(p, ec);
}

}  // namespace

// What to remove when the process is interrupted (SIGINT, SIGTERM, SIGHUP, and SIGPIPE: a
// reader gone, as in `quadgen derive ... 2>&1 | head -1`, ends the run at its next line of
// progress; gnuplot is written to with MSG_NOSIGNAL, runtime/plot.cpp): the staging
// directories, the files staged in them (only at the end of the work) and the folders
// created to hold them. A signal handler may call unlink and rmdir but not walk a tree, so
// each path is remembered as it is made: a folder is created, a file named, and each
// remembered with those signals blocked (Blocked), so none arrives between the two. The
// staged files are forgotten once the staging directory has moved into place, with the
// signals blocked between (after the exchange with an earlier run the staging path holds
// that run's files, which are not this run's to remove); OutputFiles moves its files out
// one by one and leaves their staged paths empty. A path of kPathBytes or more, or more
// paths at once than a table has slots, is not remembered: left to the next run.
namespace interrupt {
constexpr size_t kPathBytes = 4096;
constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};
static_assert(std::atomic<int>::is_always_lock_free, "read in a signal handler");

// Paths a handler may read: a slot's `used` is published after its path is written.
template <int N>
struct Slots {
  char paths[N][kPathBytes];
  std::atomic<int> used[N];

  int remember(const fs::path& p) {
    const std::string s = p.string();
    if (s.size() >= kPathBytes) return -1;
    for (int i = 0; i < N; ++i)
      if (!used[i].load(std::memory_order_acquire)) {
        std::memcpy(paths[i], s.c_str(), s.size() + 1);
        used[i].store(1, std::memory_order_release);
        return i;
      }
    return -1;  // more at once than there are slots: left to the next run
  }
  void forget(int slot) {
    if (slot >= 0) used[slot].store(0, std::memory_order_release);
  }
};
Slots<32> folders;  // staging directories and the folders made for them
Slots<64> files;    // files staged in them (a diagnosis stages about 25)

void on_signal(int sig) {
  // The staged files first (unlink, as rmdir, may be called in a handler; walking a tree may
  // not), then passes over the folders until nothing more goes: a folder empties once the
  // one inside it is gone.
  for (int i = 0; i < static_cast<int>(std::size(files.used)); ++i)
    if (files.used[i].load(std::memory_order_acquire)) ::unlink(files.paths[i]);
  for (bool removed = true; removed;) {
    removed = false;
    for (int i = static_cast<int>(std::size(folders.used)) - 1; i >= 0; --i)
      if (folders.used[i].load(std::memory_order_acquire) && ::rmdir(folders.paths[i]) == 0) {  // only if empty
        folders.used[i].store(0, std::memory_order_relaxed);
        removed = true;
      }
  }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// The interrupt signals blocked on this thread while it lives.
class Blocked {
 public:
  Blocked() {
    sigset_t set;
    sigemptyset(&set);
    for (int sig : kSignals) sigaddset(&set, sig);
    ::pthread_sigmask(SIG_BLOCK, &set, &old_);
  }
  ~Blocked() { ::pthread_sigmask(SIG_SETMASK, &old_, nullptr); }

 private:
  sigset_t old_;
};
}  // namespace interrupt

// ".<target>.quadgen-tmp.": the start of the target's staging folders' names. A long target
// name is cut (a file name has 255 bytes) and told apart from others with the same start by
// a hash of the whole name, so that one output never takes another's folders for its own.
std::string detail::staging_stem(const std::string& target_name) {
  if (target_name.size() <= 100) return "." + target_name + kStagingInfix;
  Fnv1a h;
  h.add(target_name.data(), target_name.size());
  return "." + target_name.substr(0, 100) + "~" + h.hex() + kStagingInfix;
}

// The pid in a staging folder's name <stem><pid>.XXXXXX, or -1 when the name is not one.
long detail::staging_pid(const std::string& name, const std::string& stem) {
  if (name.rfind(stem, 0) != 0) return -1;
  const std::string rest = name.substr(stem.size());
  const size_t dot = rest.find('.');
  if (dot == 0 || dot == std::string::npos || dot > 18 || rest.size() != dot + 7) return -1;
  const auto is_digit = [](char c) { return c >= '0' && c <= '9'; };
  const auto is_alnum = [&](char c) { return is_digit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  if (!std::all_of(rest.begin(), rest.begin() + dot, is_digit)) return -1;
  if (!std::all_of(rest.begin() + dot + 1, rest.end(), is_alnum)) return -1;
  return std::strtol(rest.c_str(), nullptr, 10);
}

// A private directory beside the target (same file system, so renames are atomic), named
// .<target>.quadgen-tmp.<pid>.XXXXXX. Removed with everything in it unless released.
class StagingDirectory {
 public:
  StagingDirectory(const fs::path& parent, const std::string& target_name) {
    const std::string stem = detail::staging_stem(target_name);
    remove_stale(parent, stem);
    std::string templ = (parent / (stem + std::to_string(::getpid()) + ".XXXXXX")).string();
    const interrupt::Blocked blocked;  // made and remembered as one step
    if (!::mkdtemp(templ.data())) fail(parent, "cannot create a staging directory: " + errno_text());
    path_ = templ;
    slot_ = interrupt::folders.remember(path_);
  }
  ~StagingDirectory() {
    const interrupt::Blocked blocked;  // removed and forgotten as one step
    if (!released_) remove_tree_quietly(path_);
    forget_files();
    interrupt::folders.forget(slot_);
  }
  const fs::path& path() const { return path_; }
  void release() {
    forget_files();
    interrupt::folders.forget(slot_);
    slot_ = -1;
    released_ = true;
  }
  // Moves the staging directory into place (`op`, a rename or an exchange; errno in `why`)
  // and forgets its files if it moved, with the signals blocked between: from then on the
  // staging path holds nothing of this run's (after an exchange, the earlier run's files).
  bool move(const std::function<bool()>& op, int* why) {
    const interrupt::Blocked blocked;
    const bool moved = op();
    *why = errno;
    if (moved) forget_files();
    return moved;
  }
  void forget_files() {
    for (int slot : file_slots_) interrupt::files.forget(slot);
    file_slots_.clear();
  }

  void write(const std::string& name, const std::string& content) {
    const fs::path p = path_ / name;
    {
      const interrupt::Blocked blocked;  // remembered before it exists: never there unremembered
      file_slots_.push_back(interrupt::files.remember(p));
    }
    const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) fail(p, "cannot create: " + errno_text());
    size_t done = 0;
    while (done < content.size()) {
      const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const std::string why = errno_text();
        ::close(fd);
        fail(p, "write failed (" + why + ")");
      }
      done += static_cast<size_t>(n);
    }
    const bool synced = ::fsync(fd) == 0;
    const std::string why = errno_text();
    if (::close(fd) != 0 || !synced) fail(p, "write failed (" + why + ")");
  }

 private:
  // Staging directories of runs that were killed: their process is gone. Those of running
  // processes are never touched.
  // Only a folder named exactly as this class names its own counts: <stem><pid>.XXXXXX, the
  // pid in digits and mkdtemp's six letters or digits. A user's ".res.quadgen-tmp.notes"
  // beside --out res is not quadgen's to remove.
  static void remove_stale(const fs::path& parent, const std::string& stem) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(parent, ec)) {
      const long pid = detail::staging_pid(e.path().filename().string(), stem);
      std::error_code type_ec;
      if (pid <= 0 || !fs::is_directory(fs::symlink_status(e.path(), type_ec))) continue;
      std::error_code keep_ec;
      if (fs::exists(e.path() / kKeepMarker, keep_ec)) continue;  // an earlier run kept aside where it was
      if (!process_alive(pid)) remove_tree_quietly(e.path());
    }
  }

  fs::path path_;
  bool released_ = false;
  int slot_ = -1;               // in interrupt::folders
  std::vector<int> file_slots_;  // in interrupt::files
};

namespace {

// Test hook: die after everything is staged and before anything is renamed, as a killed
// process would (tests/test_robustness.cpp).
void test_hook_die_before_commit() {
  if (std::getenv("QUADGEN_TEST_DIE_BEFORE_COMMIT")) _exit(70);
}

// Test hook: QUADGEN_TEST_SIGNAL=<place>:<signal> raises the signal at that place of a commit
// ("before-commit", "before-exchange", "after-exchange"), as an interrupt arriving there would.
void test_hook_signal(const char* place) {
  const char* spec = std::getenv("QUADGEN_TEST_SIGNAL");
  if (!spec) return;
  const std::string s(spec), p(place);
  if (s.size() > p.size() && s.compare(0, p.size(), p) == 0 && s[p.size()] == ':')
    ::raise(std::atoi(s.c_str() + p.size() + 1));
}

}  // namespace

// Where an earlier run's folder goes when it still holds files after its own were removed
// (files that appeared while this run wrote): a visible name of its own beside the output
// (a short one if the output's name is too long to extend). It is marked first, so that even
// where no rename succeeds no later run takes it for a stale staging folder and removes it.
// The marker is written without following a link: one planted under its name by whoever could
// write to the earlier output would have had this run overwrite the file it points to.
fs::path detail::keep_aside(const fs::path& staged, const fs::path& target) {
  const fs::path marker = staged / kKeepMarker;
  ::unlink(marker.c_str());  // a link or an older marker: replaced; O_EXCL refuses one planted since
  const int fd = ::open(marker.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd >= 0) {
    const std::string text = "an earlier quadgen output, kept because it held files quadgen did not write\n";
    const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
    ::close(fd);
    (void)written;  // a best effort: the folder is kept aside either way
  }
  const std::string pid = std::to_string(::getpid());
  for (const std::string& stem : {target.filename().string() + ".previous-" + pid, "quadgen-previous-" + pid})
    for (int n = 0; n < 100; ++n) {
      const fs::path kept = target.parent_path() / (stem + (n ? "-" + std::to_string(n) : ""));
      std::error_code ec;
      if (fs::exists(fs::symlink_status(kept, ec))) continue;
      if (::rename(staged.c_str(), kept.c_str()) == 0) return kept;
      if (errno == ENAMETOOLONG) break;
    }
  return staged;
}

namespace {

// After the exchange, the earlier run sits in `staged`: its own files go (those that still
// match its manifest), anything else is kept aside (said; false then).
bool remove_earlier_run(const fs::path& staged, const fs::path& target) {
  const Manifest earlier = read_manifest(staged);
  std::error_code ec;
  for (const auto& [name, hash_size] : earlier.files)
    if (unchanged_since(staged / name, hash_size, earlier)) fs::remove(staged / name, ec);
  fs::remove(staged / kManifestName, ec);
  if (fs::remove(staged, ec)) return true;
  // Kept aside and marked before it is said: the note may be the write that meets a closed
  // pipe (SIGPIPE), and a folder left under its staging name unmarked is swept as stale.
  const fs::path kept = detail::keep_aside(staged, target);
  std::cerr << "quadgen: note: the previous output was kept at " << printable(kept.string())
            << " (it held files that appeared or changed while this run wrote)\n";
  return false;
}

}  // namespace

void CreatedFolders::create(const fs::path& folder) {
  std::vector<fs::path> missing;
  std::error_code ec;
  for (fs::path p = folder; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
    missing.insert(missing.begin(), p);
    if (p == p.parent_path()) break;
  }
  const interrupt::Blocked blocked;  // made and remembered as one step
  fs::create_directories(folder, ec);
  if (ec) fail(folder, "cannot create the directory: " + ec.message());
  created_ = missing;
  for (const auto& p : created_) slots_.push_back(interrupt::folders.remember(p));
}

void CreatedFolders::keep() {
  for (int slot : slots_) interrupt::folders.forget(slot);
  slots_.clear();
  created_.clear();
}

CreatedFolders::~CreatedFolders() {
  std::error_code ec;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);  // only if empty
  for (int slot : slots_) interrupt::folders.forget(slot);
}

void remove_empty_outputs_on_interrupt() {
  struct sigaction sa {};
  sa.sa_handler = interrupt::on_signal;
  sigemptyset(&sa.sa_mask);
  for (int sig : interrupt::kSignals) {
    // A signal the caller ignores stays ignored: under nohup, SIGHUP must not end the run, nor
    // SIGINT a job a non-interactive shell started in the background.
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &sa, nullptr);
  }
}

OutputDirectory::OutputDirectory(const std::string& dir, const std::string& command, const std::vector<std::string>& inputs)
    : command_(command), inputs_(inputs) {
  const fs::path target = resolved(dir);
  dir_ = target.string();
  check_name_lengths(target);
  check_not_above_working_directory(target);
  // The rule simulate's files follow, for every folder the run would create: a folder "x " or
  // one with a line break in its name is a slip of a script or a paste more often than a wish
  // (a review, helper-135; the parents too, helper-137). Folders that exist are the user's.
  std::error_code ec;
  for (fs::path p = target; p.has_filename() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path())
    if (!plain_file_name(p.filename().string()))
      fail(p, "cannot be an output folder name (a control character or line break in it, a blank at its start or "
              "end, or a name beginning '.quadgen'); choose another");
  check_not_input(target, inputs_);
  refuse_links_that_lead_nowhere(target);
  check_replaceable(target, command_);
  created_.create(target.parent_path());
  staging_ = std::make_unique<StagingDirectory>(target.parent_path(), target.filename().string());
}

OutputDirectory::~OutputDirectory() = default;

void OutputDirectory::add(const std::string& filename, const std::string& content) {
  check_file_name(filename);
  for (const auto& m : manifest_)
    if (m.first == filename) throw OutputError("internal: " + filename + " added twice to one output set");
  staging_->write(filename, content);
  manifest_.push_back({filename, fnv1a_hex(content) + " " + std::to_string(content.size())});
}

void OutputDirectory::commit() {
  staging_->write(kManifestName, manifest_text(command_, {manifest_.begin(), manifest_.end()}));
  fsync_path(staging_->path(), O_RDONLY | O_DIRECTORY);
  test_hook_die_before_commit();
  test_hook_signal("before-commit");
  const fs::path target(dir_), staged = staging_->path();
  // A new or empty target: one plain rename. An earlier run in the way: one atomic exchange,
  // after which the earlier run sits in the staging path and is removed file by file. The
  // staged files are forgotten once moved, with the signals blocked between (not before: a
  // signal in the checks before the exchange must still find them).
  set_published_mode(staged, target);
  int why = 0;
  if (!staging_->move([&] { return ::rename(staged.c_str(), target.c_str()) == 0; }, &why)) {
    if (why != ENOTEMPTY && why != EEXIST)
      fail(target, "cannot move the output into place: " + std::string(std::strerror(why)));
    check_replaceable(target, command_);
    check_not_input(target, inputs_);
    test_hook_signal("before-exchange");
    const auto exchange = [&] {
      return ::renameat2(AT_FDCWD, staged.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0;
    };
    if (!staging_->move(exchange, &why))
      fail(target, "cannot switch the output into place: " + std::string(std::strerror(why)));
    test_hook_signal("after-exchange");
    replaced_ = remove_earlier_run(staged, target);
  }
  staging_->release();
  created_.keep();
  fsync_path(target.parent_path(), O_RDONLY | O_DIRECTORY);
}

OutputFiles::OutputFiles(const std::vector<std::string>& paths, const std::string& command, const std::vector<std::string>& inputs)
    : command_(command), written_(paths.size(), false) {
  const auto ids = identities(inputs);
  std::set<fs::path> seen;
  std::error_code ec;
  for (const auto& name : paths) {
    const fs::path p = resolved_file(name);
    check_name_lengths(p);
    if (!plain_file_name(p.filename().string()))
      fail(p, "cannot be an output file name (a control character or line break in it, a blank at its start or end, "
              "or a name beginning '.quadgen'); choose another");
    if (!seen.insert(p).second) fail(p, "is named for two outputs of one run (the trajectory and its plot)");
    if (p.parent_path() != resolved_file(paths.front()).parent_path()) throw OutputError("internal: outputs in two folders");
    if (const auto id = file_id(p.string()); id && ids.count(*id))
      fail(p, "is the input " + printable(ids.at(*id)) + "; choose another output path");
    paths_.push_back(p.string());
    named_.push_back(name);
  }
  const fs::path parent = fs::path(paths_.front()).parent_path();
  refuse_links_that_lead_nowhere(parent);
  std::error_code manifest_ec;
  if (fs::exists(fs::symlink_status(parent / kManifestName, manifest_ec)))
    fail(parent, "is the output directory of another quadgen run (it holds " + std::string(kManifestName) +
                     "); a file written there would make it refuse its next run: choose another folder");
  // The records are replaced at the end, after the files are moved: one that cannot be (a
  // directory there) failed the run with its files already in place (helper-146).
  for (const char* name : {kFilesRecordName, kPendingRecordName}) {
    struct stat st {};
    if (::lstat((parent / name).c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      fail(parent / name, "exists and is not a regular file (a link or a directory): quadgen keeps its record of the "
                          "files it wrote there under this name; remove it or choose another folder");
  }
  // A file already at a path is replaced only if the record beside it says this command
  // wrote it there and it is unchanged since: a flight log of the user's looks like a
  // trajectory, a plot of theirs may be gnuplot's too.
  const Manifest record = read_files_record(parent / kFilesRecordName);
  const std::map<std::string, std::string> pending = still_pending(parent);
  for (const auto& path : paths_) {
    const fs::path p(path);
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) continue;
    if (!S_ISREG(st.st_mode)) fail(p, "exists and is not a regular file (a link or a directory); choose another path");
    const auto it = record.files.find(p.filename().string());
    const bool recorded = record.command == command_ && it != record.files.end() && unchanged_since(p, it->second, record);
    if (!recorded && !pending.count(p.filename().string()))
      fail(p, "exists and is not a file 'quadgen " + command_ + "' wrote there (or it was changed since); choose another path or remove it");
  }
  created_.create(parent);
  staging_ = std::make_unique<StagingDirectory>(parent, fs::path(paths_.front()).filename().string());
}

OutputFiles::~OutputFiles() = default;

void OutputFiles::set(size_t i, const std::string& content) {
  staging_->write(fs::path(paths_.at(i)).filename().string(), content);
  written_[i] = true;
}

void OutputFiles::commit() {
  test_hook_die_before_commit();
  test_hook_signal("before-commit");
  std::error_code ec;
  // The constructor let through only files this command wrote here, unchanged since.
  for (size_t i = 0; i < paths_.size(); ++i)
    if (std::error_code e; fs::exists(fs::symlink_status(paths_[i], e))) replaced_.push_back(named_[i]);
  const fs::path parent = fs::path(paths_.front()).parent_path();
  // A pending record left by a run killed in its moves keeps vouching for its files until a
  // record takes them over (a review: replacing it lost them when a run to another path in
  // the folder committed).
  std::map<std::string, std::string> moving = still_pending(parent);
  for (size_t i = 0; i < paths_.size(); ++i) {
    const std::string name = fs::path(paths_[i]).filename().string();
    if (written_[i]) moving[name] = hash_and_size(staging_->path() / name);
  }
  staging_->write(kPendingRecordName, manifest_text(command_, moving));
  const fs::path staged_pending = staging_->path() / kPendingRecordName;
  if (::rename(staged_pending.c_str(), (parent / kPendingRecordName).c_str()) != 0)
    fail(parent / kPendingRecordName, "cannot move into place: " + errno_text());
  for (size_t i = 1; i < paths_.size(); ++i) fs::remove(paths_[i], ec);  // no companion of another run
  for (size_t i = 0; i < paths_.size(); ++i) {
    if (!written_[i]) continue;
    const fs::path staged = staging_->path() / fs::path(paths_[i]).filename();
    if (::rename(staged.c_str(), paths_[i].c_str()) != 0) fail(paths_[i], "cannot move into place: " + errno_text());
    test_hook_signal("after-a-file-moved");
  }
  update_record();
  fs::remove(parent / kPendingRecordName, ec);
  created_.keep();
  fsync_path(parent, O_RDONLY | O_DIRECTORY);
}

// The entries of the pending record beside the files (kPendingRecordName) whose files still
// hold what it says: a run killed in its moves wrote them, as this command.
std::map<std::string, std::string> OutputFiles::still_pending(const fs::path& parent) const {
  const Manifest pending = read_files_record(parent / kPendingRecordName);
  std::map<std::string, std::string> out;
  if (pending.command != command_) return out;
  for (const auto& [name, hash_size] : pending.files)
    if (unchanged_since(parent / name, hash_size, pending)) out[name] = hash_size;
  return out;
}

// The record beside the files: this run's files with their hashes, the entries of earlier
// runs kept where their files are still there (and those a killed run's pending record
// vouches for); replaced whole by a rename.
void OutputFiles::update_record() {
  const fs::path parent = fs::path(paths_.front()).parent_path(), record_path = parent / kFilesRecordName;
  Manifest record = read_files_record(record_path);
  if (record.command != command_) record.files.clear();
  for (const auto& [name, hash_size] : still_pending(parent)) record.files[name] = hash_size;  // a killed run's
  for (auto it = record.files.begin(); it != record.files.end();) {
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(parent / it->first, ec))) {
      it = record.files.erase(it);
      continue;
    }
    // An entry of a record under the old hash basis, rewritten under the published one (the
    // record is written anew below) if its file is unchanged; a changed one stays as it was.
    if (record.old_basis && unchanged_since(parent / it->first, it->second, record))
      it->second = hash_and_size(parent / it->first);
    ++it;
  }
  for (size_t i = 0; i < paths_.size(); ++i) {
    const std::string name = fs::path(paths_[i]).filename().string();
    if (written_[i]) record.files[name] = hash_and_size(paths_[i]);
    else record.files.erase(name);
  }
  staging_->write(kFilesRecordName, manifest_text(command_, record.files));
  const fs::path staged = staging_->path() / kFilesRecordName;
  if (::rename(staged.c_str(), record_path.c_str()) != 0) fail(record_path, "cannot move into place: " + errno_text());
}

bool complete_output_directory(const std::string& dir, std::string* why) {
  auto no = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  const Manifest m = read_manifest(dir);
  if (!m.present || m.files.empty()) return no("no manifest");
  if (!m.bad_lines.empty()) return no("the manifest is not one quadgen writes");
  std::error_code ec;
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name == kManifestName) continue;
    ++files;
    const auto it = m.files.find(name);
    if (it == m.files.end()) return no(name + " is not in the manifest");
    if (!unchanged_since(e.path(), it->second, m)) return no(name + " differs from the manifest");
  }
  if (files != m.files.size()) return no("files listed in the manifest are missing");
  return true;
}

}  // namespace quadgen::output
