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
//   a directory, a device (/dev/null, a terminal), a FIFO, a socket
//                       refused with InputError (exit status 2): renaming over them would
//                       replace a special file by a regular one, or fail half-way
//
// A reader of the output never sees a half-written file.

#include <string>

namespace artcal {

/// The name `-o` takes for standard output.
inline constexpr const char* kStandardOutput = "-";

/// InputError (file: the path) when `path` names something an output may not replace (see
/// above). Commands call it before their work, so that a long run does not end in a refusal.
void checkOutputPath(const std::string& path);

/// The regular file `path` resolves to: symbolic links followed, relative link targets taken
/// relative to the link's folder. The path itself when it is not a link.
std::string resolveOutputPath(const std::string& path);

/// Writes `content` where `path` says (see above); InputError when refused or not writable.
void writeOutputFile(const std::string& path, const std::string& content);

/// Writes `content` to the regular file `path` through a temporary file in the same folder and a
/// rename (an existing file keeps its permissions; a new one gets 0644 less the umask). No
/// symbolic-link or special-file handling: writeOutputFile does that. std::runtime_error on
/// failure, the temporary file removed.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace artcal
