#include "app/output_set.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "image/image.h"

namespace pxf {

namespace {

namespace fs = std::filesystem;

const std::string kSetPrefix = ".pxf-set-";
const std::string kCommitLinkPrefix = ".pxf-link-";
const std::string kLegacyStagingPrefix = ".pxf-staging-";  // pxf before the linked sets

std::string system_error(int error) { return std::strerror(error); }

// This host's name with '-' replaced, so that it parses as one field of a set folder's name.
const std::string& host_field() {
  static const std::string host = [] {
    char name[256] = {};
    if (::gethostname(name, sizeof(name) - 1) != 0 || !name[0]) return std::string("localhost");
    std::string h(name);
    for (char& c : h)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.') c = '_';
    return h;
  }();
  return host;
}

bool all_digits(const std::string& s) {
  return !s.empty() && s.size() <= 10 && s.find_first_not_of("0123456789") == std::string::npos;
}

bool process_is_gone(const std::string& pid_text) {
  if (!all_digits(pid_text)) return false;
  const long pid = std::stol(pid_text);
  return pid > 0 && pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// "<host>-<pid>-<seq>" after a prefix: whether the host is this one and the pid is gone.
bool owner_is_gone(const std::string& rest) {
  const std::string own = host_field() + "-";
  if (rest.compare(0, own.size(), own) != 0) return false;
  const std::string pid_and_sequence = rest.substr(own.size());
  const size_t dash = pid_and_sequence.find('-');
  return dash != std::string::npos && all_digits(pid_and_sequence.substr(dash + 1)) &&
         process_is_gone(pid_and_sequence.substr(0, dash));
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// "<name>.tmp-<pid>" for one of `names` (what write_file_atomically and the link step make).
bool is_own_temporary_file(const std::string& entry, const std::vector<std::string>& names) {
  for (const std::string& name : names)
    if (starts_with(entry, name + ".tmp-") && process_is_gone(entry.substr(name.size() + 5))) return true;
  return false;
}

std::string read_link(const std::string& path) {
  char target[4096];
  const ssize_t n = ::readlink(path.c_str(), target, sizeof(target) - 1);
  return n > 0 ? std::string(target, static_cast<size_t>(n)) : std::string();
}

// The names a set folder (or DIR, without links) was committed with: its manifest, one a line.
// A line that could reach outside the folder is not a name pxf wrote, and is skipped.
std::vector<std::string> read_manifest(const std::string& folder) {
  std::vector<std::string> names;
  std::ifstream in(folder + "/" + kSetManifest);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line != "." && line != ".." && line.find('/') == std::string::npos) names.push_back(line);
  return names;
}

void write_manifest(const std::string& folder, const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += name + "\n";
  write_file_completely(folder + "/" + kSetManifest, text.data(), text.size());
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Removes a set folder's own files (the names of its manifest and `names`, their temporaries and
// the manifest) and then the folder if nothing else is in it: a file someone else put there stays,
// and so does the folder.
void remove_set_folder(const std::string& folder, std::vector<std::string> names) {
  for (const std::string& name : read_manifest(folder))
    if (!contains(names, name)) names.push_back(name);
  names.push_back(kSetManifest);
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    const bool own = contains(names, name) ||
                     std::any_of(names.begin(), names.end(),
                                 [&](const std::string& n) { return starts_with(name, n + ".tmp-"); });
    if (own && !entry.is_directory(ec)) ::unlink(entry.path().c_str());
  }
  ::rmdir(folder.c_str());
}

// An exclusive flock on the output folder for the scope, so that two commits into one folder do
// not interleave. The kernel drops it when the process dies, whatever kills it.
class FolderLock {
 public:
  explicit FolderLock(const std::string& dir) : fd_(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)) {
    // Without a lock (a file system that has none) the commit is still atomic for one writer.
    while (fd_ >= 0 && ::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
  ~FolderLock() {
    if (fd_ >= 0) ::close(fd_);
  }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

 private:
  int fd_;
};

bool links_unsupported(int error) { return error == EPERM || error == EOPNOTSUPP || error == ENOSYS; }

// Puts a link at `path` pointing at `target`, replacing what is there in one rename; returns errno.
int place_link(const std::string& target, const std::string& path, const std::string& temporary) {
  ::unlink(temporary.c_str());
  if (::symlink(target.c_str(), temporary.c_str()) != 0) return errno;
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(temporary.c_str());
    return error;
  }
  return 0;
}

std::string make_set_folder(const std::string& dir, const std::vector<std::string>& names) {
  static std::atomic<unsigned> sequence{0};
  for (;;) {
    const std::string name = set_folder_name(::getpid(), sequence++);
    const std::string path = dir + "/" + name;
    // A folder of this name is a leftover of an earlier process that had our pid.
    if (::access(path.c_str(), F_OK) == 0) remove_set_folder(path, names);
    if (::mkdir(path.c_str(), 0777) == 0) return name;
    if (errno != EEXIST) throw Error(path + ": cannot create: " + system_error(errno));
  }
}

std::string current_link_target(const std::string& name) { return std::string(kCurrentSetLink) + "/" + name; }

// What DIR/.pxf-output points at when pxf made it: one of its set folders, beside it.
bool is_own_set_link_target(const std::string& target) {
  return starts_with(target, kSetPrefix) && target.find('/') == std::string::npos;
}

// Throws unless DIR/.pxf-output is absent or a link pxf made: a user's folder or file of that name
// is neither used nor replaced.
void refuse_foreign_current_link(const std::string& dir) {
  const std::string path = dir + "/" + kCurrentSetLink;
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    throw Error(path + ": cannot read: " + system_error(errno));
  }
  if (S_ISLNK(st.st_mode) && is_own_set_link_target(read_link(path))) return;
  const char* what = S_ISDIR(st.st_mode) ? "a folder" : S_ISLNK(st.st_mode) ? "a link" : "a file";
  throw Error(path + ": " + what + " that pxf did not make; pxf writes its output set there, so move it away or choose "
              "another output folder");
}

// After the switch, the links DIR/<x> -> .pxf-output/<x> of the replaced set whose name the new set
// lacks point at nothing: they go (only pxf makes a link of exactly that form).
void remove_links_outside(const std::string& dir, const std::vector<std::string>& names) {
  std::error_code ec;
  std::vector<std::string> dangling;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (!contains(names, name) && entry.is_symlink(ec) && read_link(entry.path().string()) == current_link_target(name))
      dangling.push_back(entry.path().string());
  }
  for (const std::string& path : dangling) ::unlink(path.c_str());
}

// DIR/.pxf-link-<host>-<pid>-<use>: the temporary link that is renamed over DIR/.pxf-output.
std::string commit_link_path(const std::string& dir, int use) {
  return dir + "/" + kCommitLinkPrefix + host_field() + "-" + std::to_string(::getpid()) + "-" + std::to_string(use);
}

}  // namespace

std::string set_folder_name(long pid, unsigned sequence) {
  return kSetPrefix + host_field() + "-" + std::to_string(pid) + "-" + std::to_string(sequence);
}

bool is_stale_temporary(const std::string& name, const std::vector<std::string>& names,
                        const std::string& current_set) {
  if (starts_with(name, kSetPrefix)) return name != current_set && owner_is_gone(name.substr(kSetPrefix.size()));
  if (starts_with(name, kCommitLinkPrefix)) return owner_is_gone(name.substr(kCommitLinkPrefix.size()));
  if (starts_with(name, kLegacyStagingPrefix)) return process_is_gone(name.substr(kLegacyStagingPrefix.size()));
  return is_own_temporary_file(name, names);
}

void remove_stale_temporaries(const std::string& dir, const std::vector<std::string>& names) {
  const std::string current = read_link(dir + "/" + kCurrentSetLink);
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (is_stale_temporary(entry.path().filename().string(), names, current)) stale.push_back(entry.path());
  for (const fs::path& path : stale) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0) continue;
    if (S_ISDIR(st.st_mode)) remove_set_folder(path.string(), names);
    else ::unlink(path.c_str());
  }
}

void check_output_folder(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create output folder: " + ec.message());
  refuse_foreign_current_link(dir);
  // A probe of the commit link's name (a set folder's would take a set's sequence number).
  const std::string probe = commit_link_path(dir, 2);
  if (::mkdir(probe.c_str(), 0777) != 0 && errno != EEXIST)
    throw Error(dir + ": cannot write into the output folder: " + system_error(errno));
  ::rmdir(probe.c_str());
}

OutputSetWriter::OutputSetWriter(std::string dir, std::vector<std::string> names)
    : dir_(std::move(dir)), names_(std::move(names)) {
  check_output_folder(dir_);
  set_name_ = make_set_folder(dir_, names_);
  staging_ = dir_ + "/" + set_name_;
}

void OutputSetWriter::set_names(std::vector<std::string> names) { names_ = std::move(names); }

OutputSetWriter::~OutputSetWriter() {
  if (!committed_) remove_set_folder(staging_, names_);
}

void OutputSetWriter::commit() {
  for (const std::string& name : names_) {
    struct stat st {};
    if (::lstat((staging_ + "/" + name).c_str(), &st) != 0 || !S_ISREG(st.st_mode))
      throw Error(staging_ + "/" + name + ": not written, so the set is not committed");
    if (::lstat((dir_ + "/" + name).c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISLNK(st.st_mode))
      throw Error(dir_ + "/" + name + ": cannot replace: not a file");
  }
  refuse_foreign_current_link(dir_);
  write_manifest(staging_, names_);
  sync_folder(staging_);
  const FolderLock lock(dir_);
  const std::string commit_link = commit_link_path(dir_, 0);
  ::unlink(commit_link.c_str());
  if (::symlink(set_name_.c_str(), commit_link.c_str()) != 0) {
    if (!links_unsupported(errno)) throw Error(commit_link + ": cannot create: " + system_error(errno));
    replace_file_by_file();
    return;
  }
  adopt_plain_files();
  const std::string previous = read_link(dir_ + "/" + kCurrentSetLink);
  link_every_name();
  if (::rename(commit_link.c_str(), (dir_ + "/" + kCurrentSetLink).c_str()) != 0) {
    const int error = errno;
    ::unlink(commit_link.c_str());
    throw Error(dir_ + "/" + kCurrentSetLink + ": cannot switch to the new output set: " + system_error(error));
  }
  sync_folder(dir_);
  committed_ = true;
  remove_links_outside(dir_, names_);
  if (is_own_set_link_target(previous) && previous != set_name_) remove_set_folder(dir_ + "/" + previous, names_);
  remove_stale_temporaries(dir_, names_);
}

// A folder whose outputs are plain files (written by an earlier pxf, or copied there) and that has
// no current set yet: the plain files become the current set first, through hard links (a copy
// where the file system has none), so that they stay visible while each name becomes a link.
void OutputSetWriter::adopt_plain_files() {
  if (!read_link(dir_ + "/" + kCurrentSetLink).empty()) return;
  std::vector<std::string> plain;
  for (const std::string& name : names_) {
    struct stat st {};
    if (::lstat((dir_ + "/" + name).c_str(), &st) == 0 && S_ISREG(st.st_mode)) plain.push_back(name);
  }
  if (plain.empty()) return;
  const std::string adopted = make_set_folder(dir_, names_);
  for (const std::string& name : plain) {
    const std::string from = dir_ + "/" + name, to = dir_ + "/" + adopted + "/" + name;
    std::error_code ec;
    if (::link(from.c_str(), to.c_str()) != 0) fs::copy_file(from, to, ec);
    if (ec) {
      remove_set_folder(dir_ + "/" + adopted, names_);
      throw Error(from + ": cannot keep the previous output while replacing it: " + ec.message());
    }
  }
  sync_folder(dir_ + "/" + adopted);
  if (const int error = place_link(adopted, dir_ + "/" + kCurrentSetLink, commit_link_path(dir_, 1))) {
    remove_set_folder(dir_ + "/" + adopted, names_);
    throw Error(dir_ + "/" + kCurrentSetLink + ": cannot create: " + system_error(error));
  }
}

// DIR/<name> -> .pxf-output/<name> for each name that is not that link already. Before the switch
// each such link shows the current set (or nothing, where there is none yet).
void OutputSetWriter::link_every_name() {
  for (const std::string& name : names_) {
    const std::string path = dir_ + "/" + name, target = current_link_target(name);
    if (read_link(path) == target) continue;
    if (const int error = place_link(target, path, path + ".tmp-" + std::to_string(::getpid())))
      throw Error(path + ": cannot link into place: " + system_error(error));
  }
}

// The fallback without symbolic links: each file is renamed over its name, never removed first.
// DIR's own manifest then names the current set, so that the next commit removes the names it
// lacks.
void OutputSetWriter::replace_file_by_file() {
  for (const std::string& name : names_) {
    const std::string from = staging_ + "/" + name, to = dir_ + "/" + name;
    if (::rename(from.c_str(), to.c_str()) != 0)
      throw Error(to + ": cannot move into place: " + system_error(errno));
  }
  const std::vector<std::string> previous = read_manifest(dir_);
  const std::string manifest = std::string(staging_) + "/" + kSetManifest;
  if (::rename(manifest.c_str(), (dir_ + "/" + kSetManifest).c_str()) != 0)
    throw Error(dir_ + "/" + kSetManifest + ": cannot move into place: " + system_error(errno));
  for (const std::string& name : previous) {
    struct stat st {};
    const std::string path = dir_ + "/" + name;
    if (!contains(names_, name) && ::lstat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode)) ::unlink(path.c_str());
  }
  sync_folder(dir_);
  committed_ = true;
  remove_set_folder(staging_, names_);
  remove_stale_temporaries(dir_, names_);
}

}  // namespace pxf
