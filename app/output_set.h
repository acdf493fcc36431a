// Replaces a set of files in a folder as one unit. After any kill, any signal in any thread, a
// crash or a second writer, DIR/<name> for every name of the set shows the whole old set or the
// whole new one: never a mix, never neither.
//
// How: each name is a relative symbolic link, DIR/<name> -> .pxf-output/<name>, and DIR/.pxf-output
// is one more link to a hidden folder, DIR/.pxf-set-<host>-<pid>-<seq>, that holds one complete set.
// A new set is written into a new such folder and committed by renaming a fresh link over
// DIR/.pxf-output, which rename(2) does atomically. Commits into one folder are serialized by an
// flock on the folder, so two writers cannot interleave their steps. Where the file system has no
// symbolic links (FAT, some network shares), each file is renamed over its name instead: every
// name then always holds a complete file, but a kill between two renames can leave a mix.
//
// A set owns its names: each set folder holds a manifest (.pxf-names) of the names it was committed
// with, and a commit removes the links of the set it replaces that the new set lacks (a 3-frame
// camera path after a 6-frame one leaves no frame-0003..5.png), then that set's folder, whole.
//
// pxf removes only what it names itself (see is_stale_temporary): a set folder, link or
// temporary file of a process that is gone, and in a set folder only the set's own file names.
// A .pxf-output that pxf did not make (the user's folder or file) is refused before anything in
// DIR is touched.
#pragma once
#include <string>
#include <vector>

namespace pxf {

class OutputSetWriter {
 public:
  // Creates DIR if needed and an empty staging folder inside it; throws pxf::Error naming DIR, or
  // naming DIR/.pxf-output where that is not pxf's (check_output_folder).
  OutputSetWriter(std::string dir, std::vector<std::string> names);
  ~OutputSetWriter();  // removes the staging folder unless committed
  OutputSetWriter(const OutputSetWriter&) = delete;
  OutputSetWriter& operator=(const OutputSetWriter&) = delete;

  // The folder to write each name of the set into before commit().
  const std::string& staging() const { return staging_; }
  // Makes the staged files the folder's current set, removes the previous set and whatever stale
  // temporaries of pxf's are in DIR; throws pxf::Error naming the file that failed, with the
  // previous set still in place.
  void commit();
  // Narrows the set to `names` before commit(), for a job that was stopped before it wrote every
  // name it planned (a camera path stopped after some frames): only these are committed.
  void set_names(std::vector<std::string> names);

 private:
  void link_every_name();
  void adopt_plain_files();
  void replace_file_by_file();

  std::string dir_, set_name_, staging_;
  std::vector<std::string> names_;
  bool committed_ = false;
};

// The link that names the current set, relative to DIR.
inline const char* const kCurrentSetLink = ".pxf-output";
// The manifest in each set folder (and in DIR on a file system without links): one name a line.
inline const char* const kSetManifest = ".pxf-names";

// Creates DIR if needed and checks, before any work, that an output set can be committed there:
// DIR/.pxf-output is absent or pxf's own link, and DIR takes a new folder. Throws pxf::Error with
// one line naming the path.
void check_output_folder(const std::string& dir);

// ".pxf-set-<host>-<pid>-<sequence>": the folder that the sequence-th set of process pid on this
// host is written into.
std::string set_folder_name(long pid, unsigned sequence);

// Whether `name`, an entry of an output folder, is a temporary that pxf made in a process on this
// host that is gone and so may be removed: a set folder (not the current one), a commit link, a
// legacy staging folder, or "<output name>.tmp-<pid>" for one of `names`. Anything else, a user's
// "report.docx.tmp-4000001" included, is never touched.
bool is_stale_temporary(const std::string& name, const std::vector<std::string>& names,
                        const std::string& current_set);

// Removes the stale temporaries (is_stale_temporary) from DIR; best effort.
void remove_stale_temporaries(const std::string& dir, const std::vector<std::string>& names);

}  // namespace pxf
