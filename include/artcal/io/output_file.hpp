#pragma once
// Where a command's output file goes (docs/plan-format.md, "Output files"): the one function every
// command that writes a file uses (`optimize -o`, `simulate -o`, `report -o`, `report --svg`,
// `calibrate --write-machine`, `import-urdf -o`, `export-urdf -o`).
//
//   "-"                 standard output
//   a regular file      replaced atomically: a temporary file in the same folder, fsync, rename
//   a symbolic link     followed (chains too): its target is replaced atomically, in the
//                       target's folder; the link stays a link
//   a new name          created the same way
//   an input of the run (the same file as the plan, the URDF, ...: noteInputFile)
//   a directory, a device (/dev/null, a terminal), a FIFO, a socket
//                       refused with InputError (exit status 2): renaming over them would
//                       replace a special file by a regular one, or fail half-way
//
// A reader of the output never sees a half-written file.

#include <string>
#include <utility>
#include <vector>

namespace artcal {

/// The name `-o` takes for standard output.
inline constexpr const char* kStandardOutput = "-";

/// Records `path` (when it exists) as an input of this run: checkOutputPath refuses an output
/// that is the same file (same device and inode, through any link or other name).
void noteInputFile(const std::string& path);

/// InputError (file: the path) when `path` names something an output may not replace (see
/// above) or an input of this run (noteInputFile). Commands call it before their work, so that a
/// long run does not end in a refusal.
void checkOutputPath(const std::string& path);

/// The regular file `path` resolves to: symbolic links followed, relative link targets taken
/// relative to the link's folder. The path itself when it is not a link.
std::string resolveOutputPath(const std::string& path);

/// Writes `content` where `path` says (see above); InputError when refused or not writable.
void writeOutputFile(const std::string& path, const std::string& content);

/// InputError unless `path` can hold the files of a multi-file output: an existing directory or
/// a new name (not "-", not a file). Commands call it before their work.
void checkOutputDirectory(const std::string& path);

/// checkOutputDirectory, then the directory created when missing (InputError when it cannot be).
void createOutputDirectory(const std::string& path);

/// Writes several files (path, content) as one output: every target checked (checkOutputPath)
/// before anything is written, each written to a temporary file beside it, and only when all are
/// written in full renamed into place; a refusal or a write failure leaves every earlier file as
/// it was.
void writeOutputFiles(const std::vector<std::pair<std::string, std::string>>& files);

/// Writes `content` to the regular file `path` through a temporary file in the same folder and a
/// rename (an existing file keeps its permissions; a new one gets 0644 less the umask). No
/// symbolic-link or special-file handling: writeOutputFile does that. std::runtime_error on
/// failure, the temporary file removed.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace artcal
