#pragma once
// The artifact registry: every artifact kind the plan format knows, by its "type" in files.
//
// A kind is two halves, as a mechanism family is (model_registry.hpp). The kind
// (src/artifact/<kind>.cpp, Eigen only) is an ArtifactKind (artifact/artifact_kind.hpp): what a
// reading values, its rigid motions, how it is planned, estimated and drawn; its factory
// (Artifact::<kind>) puts it on every artifact it builds. The codec (src/io/<kind>_codec.cpp,
// the only layer that sees JSON) reads the plan's artifact entry into that Artifact. Nothing
// outside the kind's files and this registry asks which kind an artifact is: the layers ask the
// kind what it does (tests/artifact/artifact_kinds.cmake checks it).
//
// How to add a kind "foo":
//   1. src/artifact/foo.cpp: a file-local `const ArtifactKind kFoo{.name = "foo", ...}` with its
//      rigid orders, and `Artifact Artifact::foo(...)` (declared in artifact/artifact.hpp) that
//      builds its features and systematic errors.
//   2. include/artcal/io/foo_codec.hpp + src/io/foo_codec.cpp: `ArtifactCodec fooArtifactCodec();`
//      whose read() checks the entry with Node (io/json_node.hpp: every fault names its JSON
//      pointer; warnUnknown with the kind's own fields).
//   3. One line in the table of src/io/artifact_registry.cpp: `fooArtifactCodec(),` (with its
//      #include).

#include <functional>
#include <string>
#include <vector>

#include "artcal/io/json_node.hpp"
#include "artcal/plan/plan.hpp"

namespace artcal {

/// A kind's JSON codec: reads one entry of the plan's "artifacts".
struct ArtifactCodec {
  std::string type;  ///< "type" in plan files
  /// The artifact called `id` from its entry, for `machine` (its dimension, its capabilities).
  std::function<Artifact(const std::string& id, const Node& entry, const Machine& machine,
                         std::vector<std::string>& warnings)>
      read;
};

/// The most features an artifact entry may list (balls of a plate, faces of a gauge).
inline constexpr std::size_t kMaxArtifactFeatures = 10'000;

/// An artifact's calibration uncertainty `key` (a standard deviation, mm; 0 when absent).
double artifactUncertainty(const Node& entry, const char* key);

/// Every registered kind's codec, in the order error messages list them.
const std::vector<ArtifactCodec>& artifactCodecs();

/// The artifact an entry of "artifacts" describes, through its type's codec; an unknown type
/// fails at /type naming the known ones.
Artifact readArtifact(const std::string& id, const Node& entry, const Machine& machine,
                      std::vector<std::string>& warnings);

}  // namespace artcal
