// URDF import and export (docs/urdf.md), the one part of artcal that needs urdfdom and
// tinyxml2: built as a module of its own (libartcal_urdf.so) that the io layer loads on first use
// (src/io/urdf.cpp), so that no other run of artcal loads those libraries.
#include "urdf_module.hpp"

#include <tinyxml2.h>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "artcal/core/error.hpp"
#include "artcal/core/units.hpp"
#include "artcal/io/json_node.hpp"
#include "artcal/io/plan_io.hpp"
#include "artcal/io/urdf_origin_edit.hpp"

namespace artcal::urdf_module {

namespace {

using nlohmann::json;

/// Most joints and links a URDF may hold: real robots have tens; urdfdom's tree walk recurses
/// once per level (a chain 150 000 joints deep overflowed the stack).
constexpr int kMaxUrdfElements = 4096;

// urdfdom reports through console_bridge; the first error becomes the one line the user sees,
// and nothing else reaches stderr.
class FirstError final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first.empty()) first = text;
  }
  std::string first;
};

// Both views of one URDF: the XML (for the origins' own text and the rewrite) and urdfdom's model.
struct UrdfDocument {
  std::string path;
  tinyxml2::XMLDocument xml;
  urdf::ModelInterfaceSharedPtr model;
  std::map<std::string, tinyxml2::XMLElement*> joint_elements;

  [[noreturn]] void fail(const tinyxml2::XMLElement* at, const std::string& message) const {
    throw InputError(path, at ? "line " + std::to_string(at->GetLineNum()) : "", message);
  }
};

// Links whose parents lead back to themselves (each with one parent: a cycle apart from the
// tree, which urdfdom accepts and then leaks and walks forever). Each link is walked up once.
void checkNoCycle(const UrdfDocument& doc, const std::map<std::string, std::string>& parent_of) {
  std::map<std::string, int> state;  // 1: on the current walk, 2: leads to a root
  for (const auto& entry : parent_of) {
    std::vector<std::string> walk;
    for (std::string link = entry.first; state[link] != 2;) {
      if (state[link] == 1) {
        doc.fail(nullptr, "the links above \"" + link + "\" form a loop: a URDF is a tree");
      }
      state[link] = 1;
      walk.push_back(link);
      const auto parent = parent_of.find(link);
      if (parent == parent_of.end()) break;
      link = parent->second;
    }
    for (const std::string& link : walk) state[link] = 2;
  }
}

// What urdfdom would loop or recurse on, refused from the XML before it parses: more than
// kMaxUrdfElements joints or links, a link with two parent joints, a joint that is its own
// parent (a URDF is a tree).
void checkTreeShape(const UrdfDocument& doc) {
  const tinyxml2::XMLElement* robot = doc.xml.RootElement();
  int links = 0;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("link"); e;
       e = e->NextSiblingElement("link")) {
    if (++links > kMaxUrdfElements)
      doc.fail(e, "more than " + std::to_string(kMaxUrdfElements) + " links");
  }
  std::map<std::string, std::string> parent_joint;    // child link -> joint
  std::map<std::string, std::string> parent_link_of;  // child link -> parent link
  int joints = 0;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    if (++joints > kMaxUrdfElements)
      doc.fail(e, "more than " + std::to_string(kMaxUrdfElements) + " joints");
    const tinyxml2::XMLElement* parent = e->FirstChildElement("parent");
    const tinyxml2::XMLElement* child = e->FirstChildElement("child");
    const char* parent_link = parent ? parent->Attribute("link") : nullptr;
    const char* child_link = child ? child->Attribute("link") : nullptr;
    if (!parent_link || !child_link) continue;  // urdfdom names it
    const std::string name = e->Attribute("name") ? e->Attribute("name") : "";
    if (std::string(parent_link) == child_link) {
      doc.fail(e, "joint \"" + name + "\" has link \"" + child_link +
                      "\" as both parent and child: the links must form a tree");
    }
    const auto [it, first] = parent_joint.emplace(child_link, name);
    if (!first) {
      doc.fail(e, "link \"" + std::string(child_link) + "\" is the child of joints \"" +
                      it->second + "\" and \"" + name +
                      "\": the links must form a tree (a closed loop is not a URDF chain)");
    }
    parent_link_of[child_link] = parent_link;
  }
  checkNoCycle(doc, parent_link_of);
}

// A xacro file (the macro language most robots' descriptions are written in) is no URDF until
// xacro expands it; urdfdom would only say that it found no links, or a number it cannot parse.
// An element named xacro:* anywhere in the tree (a URDF written by xacro keeps only the
// xmlns:xacro attribute) is named, with what to do.
void checkNotXacro(const UrdfDocument& doc) {
  std::vector<const tinyxml2::XMLElement*> stack = {doc.xml.RootElement()};
  while (!stack.empty()) {
    const tinyxml2::XMLElement* e = stack.back();
    stack.pop_back();
    if (std::string(e->Name()).rfind("xacro:", 0) == 0) {
      doc.fail(e, "<" + std::string(e->Name()) +
                      ">: a xacro file, not a URDF: expand it first (xacro " + doc.path +
                      " > robot.urdf) and give the URDF it writes");
    }
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement())
      stack.push_back(c);
  }
}

void loadUrdf(const UrdfSource& source, UrdfDocument& doc) {
  doc.path = source.path;
  const std::string& path = source.path;
  const std::string& text = source.text;
  if (doc.xml.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS) {
    if (doc.xml.ErrorID() == tinyxml2::XML_ERROR_EMPTY_DOCUMENT)
      throw InputError(path, "", "empty: not a URDF file (expected a <robot> root element)");
    throw InputError(path, "line " + std::to_string(doc.xml.ErrorLineNum()),
                     std::string("not well-formed XML: ") + doc.xml.ErrorName());
  }
  const tinyxml2::XMLElement* robot = doc.xml.RootElement();
  if (!robot || std::string(robot->Name()) != "robot") {
    throw InputError(path, "", "not a URDF file (expected a <robot> root element)");
  }
  checkNotXacro(doc);
  checkTreeShape(doc);
  FirstError errors;
  console_bridge::useOutputHandler(&errors);
  doc.model = urdf::parseURDF(text);
  console_bridge::restorePreviousOutputHandler();
  if (!doc.model) {
    throw InputError(path, "",
                     "not a valid URDF (" +
                         (errors.first.empty() ? "urdfdom refused it" : errors.first) +
                         "); check the links and joints it names");
  }
  for (tinyxml2::XMLElement* e = doc.xml.RootElement()->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    if (const char* name = e->Attribute("name")) doc.joint_elements[name] = e;
  }
}

// How a number of the URDF's text reads: a number within the input bound (kMaxInputMagnitude mm
// or deg), not a number at all, or a number beyond the bound (a double's range included).
enum class TextNumber { Ok, NotANumber, OutOfRange };

// The whole token as a double ("inf" and "nan" are not numbers of a URDF). A number beyond a
// double's range is OutOfRange; one below its smallest is its rounding (0 or a subnormal).
TextNumber parseDouble(const std::string& token, double& value) {
  const char* last = token.data() + token.size();
  const auto [end, error] = std::from_chars(token.data(), last, value);
  if (end != last || error == std::errc::invalid_argument) return TextNumber::NotANumber;
  if (error == std::errc::result_out_of_range) {
    const double rounded = std::strtod(token.c_str(), nullptr);
    if (!(std::abs(rounded) < 1.0)) return TextNumber::OutOfRange;
    value = rounded;
  }
  return std::isfinite(value) ? TextNumber::Ok : TextNumber::NotANumber;
}

// A number of the URDF's text in metres as mm, exactly as the decimal says: the exponent is
// shifted by 3 before conversion ("0.333" -> "0.333e3" = 333, not 0.333 * 1000).
TextNumber metresTextToMillimetres(const std::string& token, double& mm) {
  double metres = 0.0;
  if (const TextNumber read = parseDouble(token, metres); read != TextNumber::Ok) return read;
  if (!(std::abs(metres) <= kMaxInputMagnitude / 1000.0)) return TextNumber::OutOfRange;
  std::string shifted = token;
  const std::size_t e = token.find_first_of("eE");
  if (e == std::string::npos) {
    shifted += "e3";
  } else {
    int exponent = 0;
    const char* first = token.data() + e + 1;
    const char* last = token.data() + token.size();
    if (first != last && *first == '+') ++first;
    const auto [end, error] = std::from_chars(first, last, exponent);
    // An exponent beyond int of a number within the bound: a subnormal's (-1e12); its metres.
    if (error != std::errc() || end != last) {
      mm = metres * 1000.0;
      return TextNumber::Ok;
    }
    shifted = token.substr(0, e) + "e" + std::to_string(exponent + 3);
  }
  if (parseDouble(shifted, mm) != TextNumber::Ok || !(std::abs(mm) <= kMaxInputMagnitude))
    return TextNumber::OutOfRange;
  return TextNumber::Ok;
}

// A number of the URDF's text (an angle in rad, an axis component) within the input bound.
TextNumber boundedNumber(const std::string& token, double& value) {
  if (const TextNumber read = parseDouble(token, value); read != TextNumber::Ok) return read;
  return std::abs(radToDeg(value)) <= kMaxInputMagnitude ? TextNumber::Ok : TextNumber::OutOfRange;
}

// What a number of the URDF refused as `read` is: "is not a number" or beyond the bound (`bound`
// says it in the URDF's unit and in artcal's), with what to check.
std::string numberProblem(TextNumber read, const std::string& token, bool metres) {
  if (read == TextNumber::NotANumber) return "\"" + token + "\" is not a number";
  return "\"" + token + "\" is beyond " +
         (metres ? std::string("1e6 m (1e9 mm, 1000 km): check the value (a URDF's lengths are in "
                               "metres)")
                 : std::string("1.7e7 rad (1e9 deg): check the value (a URDF's angles are in "
                               "radians)"));
}

std::vector<std::string> tokens(const char* text) {
  std::istringstream in(text ? text : "");
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

// The <origin> of a joint element: xyz in mm, rpy in rad (absent: zeros, as URDF says).
struct OriginValues {
  Eigen::Vector3d xyz_mm = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
};

OriginValues readOrigin(const UrdfDocument& doc, const tinyxml2::XMLElement* joint) {
  OriginValues out;
  const tinyxml2::XMLElement* origin = joint->FirstChildElement("origin");
  if (!origin) return out;
  const auto three = [&](const char* attribute, auto convert, bool metres, Eigen::Vector3d& v) {
    const char* text = origin->Attribute(attribute);
    if (!text) return;
    const std::vector<std::string> t = tokens(text);
    if (t.size() != 3) doc.fail(origin, std::string("<origin ") + attribute + "> needs 3 numbers");
    for (int i = 0; i < 3; ++i) {
      const std::string& token = t[static_cast<std::size_t>(i)];
      if (const TextNumber read = convert(token, v[i]); read != TextNumber::Ok) {
        doc.fail(origin,
                 std::string("<origin ") + attribute + ">: " + numberProblem(read, token, metres));
      }
    }
  };
  three("xyz", metresTextToMillimetres, true, out.xyz_mm);
  three("rpy", boundedNumber, false, out.rpy);
  return out;
}

// A movable joint's <axis xyz> from the file's own text (urdfdom scales it, and a huge axis came
// out as a zero one): three numbers within the input bound, not all zero; absent: 1 0 0.
Eigen::Vector3d readAxis(const UrdfDocument& doc, const tinyxml2::XMLElement* joint,
                         const std::string& name) {
  const tinyxml2::XMLElement* axis = joint->FirstChildElement("axis");
  const char* text = axis ? axis->Attribute("xyz") : nullptr;
  if (!text) return Eigen::Vector3d::UnitX();
  const std::vector<std::string> t = tokens(text);
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (t.size() != 3 || boundedNumber(t[static_cast<std::size_t>(i)], v[i]) != TextNumber::Ok) {
      doc.fail(axis, "joint \"" + name + "\": <axis xyz> needs 3 numbers within +-1e9");
    }
  }
  if (!(v.norm() > 1e-12)) doc.fail(axis, "joint \"" + name + "\": zero <axis>");
  return v;
}

tinyxml2::XMLElement* jointElement(const UrdfDocument& doc, const std::string& name) {
  const auto it = doc.joint_elements.find(name);
  return it == doc.joint_elements.end() ? nullptr : it->second;
}

// One joint of a path through the URDF tree: reversed when the path runs it from its child link
// up to its parent.
struct PathJoint {
  urdf::JointConstSharedPtr joint;
  bool reversed = false;
};

// The joints above `link` up to the root, nearest first.
std::vector<urdf::JointConstSharedPtr> jointsAbove(const UrdfDocument& doc,
                                                   const std::string& link_name) {
  std::vector<urdf::JointConstSharedPtr> joints;
  for (urdf::LinkConstSharedPtr link = doc.model->getLink(link_name); link && link->parent_joint;
       link = doc.model->getLink(link->parent_joint->parent_link_name)) {
    if (joints.size() > doc.model->joints_.size()) {
      doc.fail(nullptr, "the links above \"" + link_name + "\" form a loop: a URDF is a tree");
    }
    joints.push_back(link->parent_joint);
  }
  return joints;
}

// The joints from `base` to `tip` in chain order: up from `base` to the links' common ancestor
// (each joint reversed: child to parent), then down to `tip` (a tip below the base: down only).
std::vector<PathJoint> chainJoints(const UrdfDocument& doc, const std::string& base,
                                   const std::string& tip) {
  for (const std::string& link : {base, tip}) {
    if (!doc.model->getLink(link)) {
      doc.fail(nullptr, "no link named \"" + link + "\" (check --base and --tip)");
    }
  }
  std::vector<urdf::JointConstSharedPtr> up = jointsAbove(doc, base);
  std::vector<urdf::JointConstSharedPtr> down = jointsAbove(doc, tip);
  // Drop the joints both walks share (above the common ancestor), from the root down.
  while (!up.empty() && !down.empty() && up.back() == down.back()) {
    up.pop_back();
    down.pop_back();
  }
  if (up.empty() && down.empty()) {
    doc.fail(nullptr, "--base and --tip name the same link: no joints between");
  }
  if (up.size() + down.size() > static_cast<std::size_t>(Chain::kMaxJoints)) {
    doc.fail(nullptr,
             "more than " + std::to_string(Chain::kMaxJoints) + " joints from base to tip");
  }
  std::vector<PathJoint> path;
  for (const urdf::JointConstSharedPtr& joint : up) path.push_back({joint, true});
  for (auto it = down.rbegin(); it != down.rend(); ++it) path.push_back({*it, false});
  return path;
}

const char* chainTypeName(const UrdfDocument& doc, const urdf::Joint& joint) {
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      return "revolute";
    case urdf::Joint::PRISMATIC:
      return "prismatic";
    case urdf::Joint::FIXED:
      return "fixed";
    default:
      doc.fail(jointElement(doc, joint.name),
               "joint \"" + joint.name +
                   "\": a chain holds revolute, continuous, prismatic and fixed joints only");
  }
}

json jointLimits(const UrdfDocument& doc, const urdf::Joint& joint) {
  if (joint.type == urdf::Joint::CONTINUOUS) return json::array({-180.0, 180.0});
  const bool prismatic = joint.type == urdf::Joint::PRISMATIC;
  if (!joint.limits || !(joint.limits->lower < joint.limits->upper)) {
    doc.fail(jointElement(doc, joint.name),
             "joint \"" + joint.name + "\": <limit> needs lower < upper");
  }
  const auto convert = [&](double v) {
    const double file = prismatic ? v * 1000.0 : radToDeg(v);
    if (!std::isfinite(file) || std::abs(file) > kMaxInputMagnitude) {
      doc.fail(jointElement(doc, joint.name),
               "joint \"" + joint.name + "\": <limit> beyond +-1e9 " + (prismatic ? "mm" : "deg"));
    }
    return file;
  };
  return json::array({convert(joint.limits->lower), convert(joint.limits->upper)});
}

json vectorJson(const Eigen::Vector3d& v) {
  return json::array({v[0], v[1], v[2]});
}

// Every rotation has two roll-pitch-yaw triples: rpyFromMatrix's, |pitch| <= 90 deg, and
// (roll + 180, 180 - pitch, yaw + 180) deg (Rz(180) Ry(180 - p) Rx(180) = Ry(p)). The one nearer
// `near` (the machine's own values, angles compared modulo a turn): a UR's shoulder origin, rpy
// (0, 90, 0) deg in its URDF, calibrated to a pitch of 90.7 deg is written as (0, 90.7, 0), not
// flipped to (-180, 89.3, -180).
Eigen::Vector3d rpyNear(const Eigen::Matrix3d& R, const Eigen::Vector3d& near) {
  constexpr double kPi = std::numbers::pi;
  const auto turn = [](double a) { return std::remainder(a, 2.0 * kPi); };
  const Eigen::Vector3d a = rpyFromMatrix(R);
  const Eigen::Vector3d b(turn(a[0] + kPi), turn(kPi - a[1]), turn(a[2] + kPi));
  const auto distance = [&](const Eigen::Vector3d& v) {
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += turn(v[i] - near[i]) * turn(v[i] - near[i]);
    return sum;
  };
  return distance(b) < distance(a) ? b : a;
}

// The origin a joint is written with: T in metres, its rpy the triple nearer `near_rpy`.
OriginEdit originEdit(const std::string& joint, const Eigen::Isometry3d& T,
                      const Eigen::Vector3d& near_rpy) {
  return {joint, T.translation() / 1000.0, rpyNear(T.linear(), near_rpy)};
}

Eigen::Isometry3d originTransform(const Eigen::Vector3d& xyz_mm, const Eigen::Vector3d& rpy) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rpyToMatrix(rpy);
  T.translation() = xyz_mm;
  return T;
}

bool typesAgree(ChainJointType type, const urdf::Joint& joint) {
  switch (type) {
    case ChainJointType::Revolute:
      return joint.type == urdf::Joint::REVOLUTE || joint.type == urdf::Joint::CONTINUOUS;
    case ChainJointType::Prismatic:
      return joint.type == urdf::Joint::PRISMATIC;
    case ChainJointType::Fixed:
      return joint.type == urdf::Joint::FIXED;
  }
  return false;
}

bool isRevolute(const urdf::Joint& joint) {
  return joint.type == urdf::Joint::REVOLUTE || joint.type == urdf::Joint::CONTINUOUS;
}

// The joint a <mimic> joint follows: it exists, is revolute, continuous or prismatic like the
// mimic (one unit for the multiplier), and is no mimic itself (which also rules out a cycle).
const urdf::Joint& mimicMaster(const UrdfDocument& doc, const urdf::Joint& joint) {
  const tinyxml2::XMLElement* element = jointElement(doc, joint.name);
  const tinyxml2::XMLElement* at = element ? element->FirstChildElement("mimic") : nullptr;
  const std::string& name = joint.mimic->joint_name;
  const std::string what = "joint \"" + joint.name + "\" mimics joint \"" + name + "\"";
  if (joint.type == urdf::Joint::FIXED) doc.fail(at, what + ", but a fixed joint does not move");
  const urdf::JointConstSharedPtr master = doc.model->getJoint(name);
  if (!master) doc.fail(at, what + ", which does not exist: check <mimic joint>");
  if (master->mimic) {
    doc.fail(at, what + ", which mimics joint \"" + master->mimic->joint_name + "\" in turn" +
                     (master->mimic->joint_name == joint.name ? " (a cycle)" : "") +
                     ": a mimic must name its driving joint");
  }
  const bool same_type =
      (isRevolute(*master) && isRevolute(joint)) ||
      (master->type == urdf::Joint::PRISMATIC && joint.type == urdf::Joint::PRISMATIC);
  if (!same_type) {
    doc.fail(at, what +
                     " of another type: a mimic and its master must both be revolute "
                     "(or continuous) or both prismatic");
  }
  return *master;
}

// "mimic": {"joint", "multiplier", "offset" (mm or deg)} from the <mimic> element's own text
// (absent attributes: multiplier 1, offset 0, as URDF says).
json mimicJson(const UrdfDocument& doc, const urdf::Joint& joint) {
  const tinyxml2::XMLElement* mimic = jointElement(doc, joint.name)->FirstChildElement("mimic");
  const auto attribute = [&](const char* name, double absent, bool metres) {
    const char* text = mimic ? mimic->Attribute(name) : nullptr;
    if (!text) return absent;
    const std::vector<std::string> t = tokens(text);
    double value = 0.0;
    if (t.size() != 1) {
      doc.fail(mimic, "joint \"" + joint.name + "\": <mimic " + name + "> needs one number");
    }
    const TextNumber read =
        metres ? metresTextToMillimetres(t[0], value) : boundedNumber(t[0], value);
    if (read != TextNumber::Ok) {
      doc.fail(mimic, "joint \"" + joint.name + "\": <mimic " + name +
                          ">: " + numberProblem(read, t[0], metres));
    }
    return value;
  };
  const bool prismatic = joint.type == urdf::Joint::PRISMATIC;
  const double offset = attribute("offset", 0.0, prismatic);
  return {{"joint", joint.mimic->joint_name},
          {"multiplier", attribute("multiplier", 1.0, false)},
          {"offset", prismatic ? offset : radToDeg(offset)}};
}

// Whether the machine's joint and the URDF's follow the same master alike (or neither mimics):
// export writes the URDF's <mimic> back as it is. Compared in the URDF's units, to rounding.
bool sameCoupling(const ChainJoint& joint, const urdf::Joint& urdf_joint) {
  if (!joint.mimic || !urdf_joint.mimic) return !joint.mimic && !urdf_joint.mimic;
  const double scale = joint.type == ChainJointType::Prismatic ? 1e-3 : 1.0;
  const auto close = [](double a, double b) {
    return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(b));
  };
  return joint.mimic->joint == urdf_joint.mimic->joint_name &&
         close(joint.mimic->multiplier, urdf_joint.mimic->multiplier) &&
         close(joint.mimic->offset * scale, urdf_joint.mimic->offset);
}

}  // namespace

json importUrdf(const UrdfSource& urdf, const std::string& base,
                const std::vector<std::string>& tips) {
  UrdfDocument doc;
  loadUrdf(urdf, doc);
  if (tips.empty()) doc.fail(nullptr, "no --tip: name the link whose origin is the probe");
  // Every tip's path; the joints once each, in the order the paths first reach them.
  std::vector<PathJoint> chain;
  std::map<std::string, bool> direction;  // joint -> reversed
  json tip_list = json::array();
  for (const std::string& tip : tips) {
    // Given twice: the same tip again counts once (options given twice, docs/hardening.md).
    if (std::any_of(tip_list.begin(), tip_list.end(),
                    [&](const json& other) { return other["name"] == tip; }))
      continue;
    json path = json::array();
    for (const PathJoint& step : chainJoints(doc, base, tip)) {
      path.push_back(step.joint->name);
      if (direction.emplace(step.joint->name, step.reversed).second) chain.push_back(step);
    }
    tip_list.push_back({{"name", tip}, {"joints", path}});
  }
  if (chain.size() > static_cast<std::size_t>(Chain::kMaxJoints)) {
    doc.fail(nullptr, "more than " + std::to_string(Chain::kMaxJoints) + " joints to the tips");
  }
  json joints = json::array(), limits = json::array();
  std::set<std::string> on_chain, masters_read;
  for (const PathJoint& step : chain) on_chain.insert(step.joint->name);
  for (const PathJoint& step : chain) {
    const urdf::JointConstSharedPtr& joint = step.joint;
    const tinyxml2::XMLElement* element = jointElement(doc, joint->name);
    if (!element) doc.fail(nullptr, "joint \"" + joint->name + "\" not found in the XML");
    const OriginValues origin = readOrigin(doc, element);
    json entry = {
        {"name", joint->name},
        {"type", chainTypeName(doc, *joint)},
        {"origin",
         {{"xyz", vectorJson(origin.xyz_mm)},
          {"rpy", vectorJson(origin.rpy.unaryExpr([](double r) { return radToDeg(r); }))}}}};
    if (joint->type != urdf::Joint::FIXED) {
      const Eigen::Vector3d axis = readAxis(doc, element, joint->name);
      entry["axis"] = vectorJson(axis);
    }
    if (joint->mimic) {
      // One reading per driving joint: an off-chain master's where its first mimic stands.
      const urdf::Joint& master = mimicMaster(doc, *joint);
      entry["mimic"] = mimicJson(doc, *joint);
      if (!on_chain.count(master.name) && masters_read.insert(master.name).second) {
        limits.push_back(jointLimits(doc, master));
      }
    } else if (joint->type != urdf::Joint::FIXED) {
      limits.push_back(jointLimits(doc, *joint));
    }
    if (step.reversed) entry["reversed"] = true;
    joints.push_back(entry);
  }
  json machine = {{"model", "chain"}, {"joints", joints}};
  if (tip_list.size() > 1) machine["tips"] = tip_list;
  if (!limits.empty()) machine["joint_limits"] = limits;
  machine["calibrate"] = "identifiable";
  return machine;
}

namespace {

// A link's own <inertial> in `frame` (the walk's frame of reference): kg, and kg mm.
void addInertial(const urdf::Link& link, const Eigen::Isometry3d& frame, double& mass,
                 Eigen::Vector3d& moment) {
  if (!link.inertial || !(link.inertial->mass > 0.0)) return;
  const urdf::Vector3& c = link.inertial->origin.position;  // metres; rpy does not move it
  mass += link.inertial->mass;
  moment += link.inertial->mass * (frame * (1000.0 * Eigen::Vector3d(c.x, c.y, c.z)));
}

// The origin transform of `joint` as the file states it (mm, rad).
Eigen::Isometry3d jointOrigin(const UrdfDocument& doc, const urdf::Joint& joint) {
  const tinyxml2::XMLElement* element = jointElement(doc, joint.name);
  if (!element) doc.fail(nullptr, "joint \"" + joint.name + "\" not found in the XML");
  const OriginValues origin = readOrigin(doc, element);
  return originTransform(origin.xyz_mm, origin.rpy);
}

// docs/compliance.md section 1: `link`'s mass with every link reached from it through joints off
// the chain (fixed ones; movable ones at their zero position), centre in `link`'s frame (mm).
json foldedMass(const UrdfDocument& doc, const std::string& link_name,
                const std::set<std::string>& chain_joints) {
  double mass = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  struct Step {
    urdf::LinkConstSharedPtr link;
    Eigen::Isometry3d frame;
    std::string came_by;
  };
  std::vector<Step> stack{{doc.model->getLink(link_name), Eigen::Isometry3d::Identity(), ""}};
  while (!stack.empty()) {
    const Step step = stack.back();
    stack.pop_back();
    addInertial(*step.link, step.frame, mass, moment);
    for (const urdf::JointSharedPtr& joint : step.link->child_joints) {
      if (chain_joints.count(joint->name) || joint->name == step.came_by) continue;
      stack.push_back({doc.model->getLink(joint->child_link_name),
                       step.frame * jointOrigin(doc, *joint), joint->name});
    }
    const urdf::JointSharedPtr& up = step.link->parent_joint;
    if (up && !chain_joints.count(up->name) && up->name != step.came_by) {
      stack.push_back({doc.model->getLink(up->parent_link_name),
                       step.frame * jointOrigin(doc, *up).inverse(), up->name});
    }
  }
  const Eigen::Vector3d centre = mass > 0.0 ? Eigen::Vector3d(moment / mass) : moment;
  return {{"mass", mass}, {"centre", vectorJson(centre)}};
}

}  // namespace

json linkMasses(const UrdfSource& urdf, const std::string& base, const std::string& tip) {
  UrdfDocument doc;
  loadUrdf(urdf, doc);
  const std::vector<PathJoint> path = chainJoints(doc, base, tip);
  std::set<std::string> chain_joints;
  for (const PathJoint& step : path) chain_joints.insert(step.joint->name);
  json masses = json::object();
  for (const PathJoint& step : path) {
    const std::string& link =
        step.reversed ? step.joint->parent_link_name : step.joint->child_link_name;
    json mass = foldedMass(doc, link, chain_joints);
    if (mass["mass"].get<double>() > 0.0) masses[step.joint->name] = std::move(mass);
  }
  return masses;
}

Eigen::VectorXd urdfNominal(const Chain& chain, const Eigen::VectorXd& p, const UrdfSource& urdf) {
  UrdfDocument doc;
  loadUrdf(urdf, doc);
  Eigen::VectorXd nominal = p;
  for (int i = 0; i < static_cast<int>(chain.joints().size()); ++i) {
    const ChainJoint& joint = chain.joints()[static_cast<std::size_t>(i)];
    const tinyxml2::XMLElement* element = jointElement(doc, joint.name);
    if (!element) continue;
    const OriginValues origin = readOrigin(doc, element);
    const int k = chain.parameterOffset(i);
    nominal.segment<3>(k) = origin.xyz_mm;
    nominal.segment<3>(k + 3) = origin.rpy;
    if (joint.type != ChainJointType::Fixed) nominal[k + 6] = 0.0;
  }
  return nominal;
}

namespace {

// Each tip's joints must follow one another through the URDF tree as the machine runs them (a
// reversed joint from its child link to its parent): else the exported origins would not give
// the machine's forward kinematics.
void checkPaths(const Chain& chain, const UrdfDocument& doc, const std::string& machine_source,
                const std::string& urdf_path) {
  const auto ends = [&](int i) {
    const ChainJoint& joint = chain.joints()[static_cast<std::size_t>(i)];
    const urdf::JointConstSharedPtr u = doc.model->getJoint(joint.name);
    return joint.reversed ? std::pair{u->child_link_name, u->parent_link_name}
                          : std::pair{u->parent_link_name, u->child_link_name};
  };
  for (std::size_t t = 0; t < chain.tips().size(); ++t) {
    const std::vector<int>& path = chain.tips()[t].joints;
    for (std::size_t j = 1; j < path.size(); ++j) {
      const auto [from, to] = ends(path[j - 1]);
      const auto [next_from, next_to] = ends(path[j]);
      if (to == next_from) continue;
      const std::string& name = chain.joints()[static_cast<std::size_t>(path[j])].name;
      const std::string where = chain.namesTips()
                                    ? "/tips/" + std::to_string(t) + "/joints/" + std::to_string(j)
                                    : "/joints/" + std::to_string(path[j]);
      throw InputError(machine_source, where,
                       "joint \"" + name + "\" starts from link \"" + next_from + "\" in " +
                           urdf_path + ", not from link \"" + to +
                           "\" where the joint before it ends (the machine's joints are not a "
                           "path of the URDF tree: export to the URDF the machine was imported "
                           "from)");
    }
  }
}

}  // namespace

std::vector<OriginEdit> calibratedOrigins(const Chain& chain, const Eigen::VectorXd& p,
                                          const UrdfSource& urdf, const std::string& machine_source,
                                          const std::vector<int>& calibrated) {
  UrdfDocument doc;
  loadUrdf(urdf, doc);
  // Each chain joint's origin, then what each joint's origin is premultiplied by: the offset of
  // the movable joint above it (a reversed joint's offset stays on its own origin).
  const int n = static_cast<int>(chain.joints().size());
  std::vector<Eigen::Isometry3d> origins;
  std::map<std::string, Eigen::Isometry3d> folds;
  std::set<std::string> in_chain;
  for (int i = 0; i < n; ++i) {
    const ChainJoint& joint = chain.joints()[static_cast<std::size_t>(i)];
    in_chain.insert(joint.name);
    const urdf::JointConstSharedPtr urdf_joint = doc.model->getJoint(joint.name);
    const std::string where = "/joints/" + std::to_string(i);
    if (!urdf_joint || !jointElement(doc, joint.name)) {
      throw InputError(machine_source, where,
                       "joint \"" + joint.name + "\" is not in " + urdf.path +
                           " (export to the URDF the machine was imported from)");
    }
    if (!sameCoupling(joint, *urdf_joint)) {
      throw InputError(machine_source, where + "/mimic",
                       "joint \"" + joint.name + "\" is coupled otherwise in " + urdf.path +
                           " (its <mimic>): export to the URDF the machine was imported from");
    }
    if (!typesAgree(joint.type, *urdf_joint)) {
      throw InputError(machine_source, where,
                       "joint \"" + joint.name + "\" has another type in " + urdf.path);
    }
    const int k = chain.parameterOffset(i);
    origins.push_back(originTransform(p.segment<3>(k), p.segment<3>(k + 3)));
    if (!Chain::isMovable(joint.type) || p[k + 6] == 0.0) continue;
    // M(q + d) = M(q) M(d) = M(d) M(q).
    Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
    if (joint.type == ChainJointType::Revolute) {
      M.linear() = axisAngleMatrix(joint.axis, p[k + 6]);
    } else {
      M.translation() = joint.axis * p[k + 6];
    }
    if (joint.reversed) {
      // Traversed upward, T(q + d)^-1 = (Trans Rot M(d) M(q))^-1: M(d) joins the joint's own
      // origin, exactly, whatever hangs from its child link (the chain's base, a sole, often
      // nothing).
      origins.back() = origins.back() * M;
      continue;
    }
    // Downward, M(d) moves to the front of every origin below this joint.
    const urdf::LinkConstSharedPtr child = doc.model->getLink(urdf_joint->child_link_name);
    if (!child || child->child_joints.empty()) {
      throw InputError(machine_source, where,
                       "joint \"" + joint.name +
                           "\" has an offset but no joint below it in the URDF to fold it into");
    }
    for (const urdf::JointSharedPtr& below : child->child_joints) folds[below->name] = M;
  }
  checkPaths(chain, doc, machine_source, urdf.path);
  // A joint none of whose parameters is calibrated, and into which no offset is folded, keeps
  // its text (docs/exports.md: the diff shows the calibrated joints only).
  const auto written = [&](int i) {
    if (calibrated.empty()) return true;
    const int begin = chain.parameterOffset(i);
    const int end = i + 1 < n ? chain.parameterOffset(i + 1) : chain.parameterCount();
    return std::any_of(calibrated.begin(), calibrated.end(),
                       [&](int k) { return k >= begin && k < end; });
  };
  std::vector<OriginEdit> edits;
  for (int i = 0; i < n; ++i) {
    const ChainJoint& joint = chain.joints()[static_cast<std::size_t>(i)];
    Eigen::Isometry3d T = origins[static_cast<std::size_t>(i)];
    const auto fold = folds.find(joint.name);
    if (fold == folds.end() && !written(i)) continue;
    if (fold != folds.end()) T = fold->second * T;
    edits.push_back(originEdit(joint.name, T, p.segment<3>(chain.parameterOffset(i) + 3)));
  }
  // Joints off the chain that hang from a link with a folded offset (e.g. a gripper's fingers).
  for (const auto& [name, M] : folds) {
    if (in_chain.count(name)) continue;
    tinyxml2::XMLElement* element = jointElement(doc, name);
    if (!element) doc.fail(nullptr, "joint \"" + name + "\" not found in the XML");
    const OriginValues origin = readOrigin(doc, element);
    edits.push_back(originEdit(name, M * originTransform(origin.xyz_mm, origin.rpy), origin.rpy));
  }
  return edits;
}

std::string exportUrdf(const Chain& chain, const Eigen::VectorXd& p, const UrdfSource& urdf,
                       const std::string& machine_source, const std::vector<int>& calibrated) {
  const std::vector<OriginEdit> edits =
      calibratedOrigins(chain, p, urdf, machine_source, calibrated);
  // The file's own text with the origins' values replaced (io/urdf_origin_edit.hpp), read back
  // here: it must be the URDF it was with these origins.
  const std::string text = editJointOrigins(urdf.text, edits, urdf.path);
  UrdfDocument check;
  loadUrdf({urdf.path, text}, check);
  for (const OriginEdit& edit : edits) {
    const OriginValues origin = readOrigin(check, jointElement(check, edit.joint));
    if ((origin.xyz_mm - edit.xyz_m * 1000.0).norm() > 1e-9 ||
        (origin.rpy - edit.rpy).norm() > 1e-12)
      check.fail(jointElement(check, edit.joint),
                 "joint \"" + edit.joint + "\": its origin could not be rewritten in place");
  }
  return text;
}

}  // namespace artcal::urdf_module
