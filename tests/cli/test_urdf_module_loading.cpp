// Where artcal loads its URDF module from (issue 44 point 1, docs/urdf.md "The module"): only
// where artcal itself is (the real path of the running program) or the absolute path of a regular
// file given in ARTCAL_URDF_MODULE; never the current folder or a folder above it. Each test runs
// the build's artcal by its name through PATH, as a user does, from a folder holding an entry
// named artcal and a planted lib/artcal/libartcal_urdf.so (tests/support/planted_module.cpp:
// loaded, it writes a marker file), and checks the planted library is never loaded while the
// import succeeds through the build tree's module.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "test_paths.hpp"

namespace urdf_module_loading_test {

using namespace artcal::test_support;
namespace fs = std::filesystem;

struct Scratch {
  fs::path dir;
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "artcal-module-XXXXXX").string();
    dir = ::mkdtemp(pattern.data());
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
};

std::string inQuotes(const fs::path& path) {
  return "'" + path.string() + "'";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A planted library and an entry named `artcal` beside it: what a checkout or a shared folder
/// holds. `at` / lib/artcal/libartcal_urdf.so.
void plant(const fs::path& at) {
  fs::create_directories(at / "lib/artcal");
  fs::copy_file(ARTCAL_PLANTED_MODULE, at / "lib/artcal/libartcal_urdf.so",
                fs::copy_options::overwrite_existing);
  std::ofstream(at / "artcal") << "#!/bin/sh\n";
}

struct ShellRun {
  int status = -1;
  std::string out, err;
};

/// `artcal ARGUMENTS` found through PATH (the build's program folder first), run in `folder`
/// with `environment` ("NAME=value ..."), under `timeout` so that a hang fails the test (exit
/// status 124) instead of stalling the suite. stderr is captured through a file in `scratch`.
ShellRun runArtcalFromPath(const fs::path& folder, const std::string& environment,
                           const std::string& arguments, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt";
  const std::string command =
      "cd " + inQuotes(folder) + " && timeout 60 env -u ARTCAL_URDF_MODULE " +
      "PATH=" + inQuotes(fs::path(ARTCAL_CLI).parent_path()) + ":/usr/bin:/bin " + environment +
      " artcal " + arguments + " 2>" + inQuotes(err);
  ShellRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.err = readText(err);
  return run;
}

std::string importArguments() {
  return "import-urdf " + inQuotes(testDataFile("urdf/ur5-ball.urdf")) +
         " --base base_link --tip ball_link";
}

/// The import succeeded through the build's own module and the planted library never ran.
void expectImportedWithoutThePlant(const ShellRun& run, const fs::path& marker) {
  EXPECT_EQ(run.status, 0) << run.err;
  EXPECT_NE(run.out.find("\"model\": \"chain\""), std::string::npos) << run.out << run.err;
  EXPECT_FALSE(fs::exists(marker)) << "the planted library was loaded: " << readText(marker);
}

TEST(UrdfModuleLoading, TheControlThePlantedLibraryMarksWhenLoaded) {
  // The marker works: the planted library named explicitly is loaded (and refused, having no
  // entry point), so the tests below that find no marker would see one had it been loaded.
  Scratch scratch;
  plant(scratch.dir);
  const fs::path marker = scratch.dir / "marker";
  const fs::path planted = scratch.dir / "lib/artcal/libartcal_urdf.so";
  const ShellRun run = runArtcalFromPath(
      scratch.dir,
      "ARTCAL_PLANTED_MARKER=" + inQuotes(marker) + " ARTCAL_URDF_MODULE=" + inQuotes(planted),
      importArguments(), scratch.dir);
  EXPECT_EQ(run.status, 2) << run.err;
  EXPECT_TRUE(fs::exists(marker));
  EXPECT_EQ(run.err.rfind("error: ARTCAL_URDF_MODULE=" + planted.string() +
                              ": not artcal's URDF module (" + planted.string() +
                              ": built for another program",
                          0),
            0u)
      << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
}

TEST(UrdfModuleLoading, ALibraryPlantedInTheCurrentFolderIsNeverLoaded) {
  Scratch scratch;
  plant(scratch.dir);
  const fs::path marker = scratch.dir / "marker";
  const ShellRun run = runArtcalFromPath(scratch.dir, "ARTCAL_PLANTED_MARKER=" + inQuotes(marker),
                                         importArguments(), scratch.dir);
  expectImportedWithoutThePlant(run, marker);
}

TEST(UrdfModuleLoading, ALibraryPlantedInAFolderAboveIsNeverLoaded) {
  Scratch scratch;
  const fs::path deep = scratch.dir / "one/two";
  fs::create_directories(deep);
  std::ofstream(deep / "artcal") << "#!/bin/sh\n";
  plant(scratch.dir / "one");  // one folder above the current one
  plant(scratch.dir);          // two folders above
  const fs::path marker = scratch.dir / "marker";
  const ShellRun run = runArtcalFromPath(deep, "ARTCAL_PLANTED_MARKER=" + inQuotes(marker),
                                         importArguments(), scratch.dir);
  expectImportedWithoutThePlant(run, marker);
}

TEST(UrdfModuleLoading, ALibraryPlantedInTheTemporaryFolderIsNeverLoaded) {
  // The world-writable temporary folder itself: anyone may create lib/artcal there.
  const fs::path temporary = fs::temp_directory_path();
  if (fs::exists(temporary / "lib")) {
    GTEST_SKIP() << temporary / "lib"
                 << " exists already: not planting into someone's folder";
  }
  Scratch scratch;
  std::ofstream(scratch.dir / "artcal") << "#!/bin/sh\n";
  struct Remove {
    fs::path path;
    ~Remove() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } planted{temporary / "lib"};
  fs::create_directories(temporary / "lib/artcal");
  fs::copy_file(ARTCAL_PLANTED_MODULE, temporary / "lib/artcal/libartcal_urdf.so");
  std::ofstream(temporary / "lib/artcal/.artcal-test-plant") << "removed after the test\n";
  const fs::path marker = scratch.dir / "marker";
  // From the scratch folder (the temporary folder one above it) and from the temporary folder.
  for (const fs::path& folder : {scratch.dir, temporary}) {
    const ShellRun run = runArtcalFromPath(folder, "ARTCAL_PLANTED_MARKER=" + inQuotes(marker),
                                           importArguments(), scratch.dir);
    expectImportedWithoutThePlant(run, marker);
  }
}

TEST(UrdfModuleLoading, TheProgramReachedThroughALinkUsesItsRealFolder) {
  // ./artcal a symbolic link beside a planted library: the module of the program the link
  // points to (the build tree's), not the link's folder's.
  Scratch scratch;
  plant(scratch.dir);
  fs::remove(scratch.dir / "artcal");
  fs::create_symlink(ARTCAL_CLI, scratch.dir / "artcal");
  const fs::path marker = scratch.dir / "marker";
  const ShellRun run =
      runArtcalFromPath(scratch.dir, "ARTCAL_PLANTED_MARKER=" + inQuotes(marker) + " PATH=.",
                        importArguments(), scratch.dir);
  expectImportedWithoutThePlant(run, marker);
}

TEST(UrdfModuleLoading, ARelativeArtcalUrdfModuleIsRefused) {
  Scratch scratch;
  plant(scratch.dir);
  const fs::path marker = scratch.dir / "marker";
  const ShellRun run = runArtcalFromPath(scratch.dir,
                                         "ARTCAL_PLANTED_MARKER=" + inQuotes(marker) +
                                             " ARTCAL_URDF_MODULE=lib/artcal/libartcal_urdf.so",
                                         importArguments(), scratch.dir);
  EXPECT_EQ(run.status, 2);
  EXPECT_EQ(run.err,
            "error: ARTCAL_URDF_MODULE=lib/artcal/libartcal_urdf.so: not an absolute path: name "
            "the module file libartcal_urdf.so by its full path, or unset it to use the "
            "installed module\n");
  EXPECT_FALSE(fs::exists(marker));
}

TEST(UrdfModuleLoading, AFifoAsArtcalUrdfModuleIsRefusedAtOnce) {
  // dlopen of a FIFO waits for a writer forever; the test runs under `timeout` (status 124 if
  // it hung), not against a clock.
  Scratch scratch;
  const fs::path fifo = scratch.dir / "module.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const ShellRun run = runArtcalFromPath(scratch.dir, "ARTCAL_URDF_MODULE=" + inQuotes(fifo),
                                         importArguments(), scratch.dir);
  EXPECT_EQ(run.status, 2) << run.err;
  EXPECT_EQ(run.err, "error: ARTCAL_URDF_MODULE=" + fifo.string() +
                         ": a FIFO, not a regular file: name the module file libartcal_urdf.so "
                         "itself, or unset it to use the installed module\n");
  EXPECT_EQ(run.out, "");
}

TEST(UrdfModuleLoading, AFolderAsArtcalUrdfModuleIsRefused) {
  Scratch scratch;
  const ShellRun run = runArtcalFromPath(scratch.dir, "ARTCAL_URDF_MODULE=" + inQuotes(scratch.dir),
                                         importArguments(), scratch.dir);
  EXPECT_EQ(run.status, 2) << run.err;
  EXPECT_EQ(run.err, "error: ARTCAL_URDF_MODULE=" + scratch.dir.string() +
                         ": a directory, not a regular file: name the module file "
                         "libartcal_urdf.so itself, or unset it to use the installed module\n");
}

}  // namespace urdf_module_loading_test
