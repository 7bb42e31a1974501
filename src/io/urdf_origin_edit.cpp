// export-urdf's edit of a URDF file in place (io/urdf_origin_edit.hpp).

#include "artcal/io/urdf_origin_edit.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

#include "artcal/core/error.hpp"

namespace artcal {

namespace {

// One attribute of a tag: its name and where its value lies (between the quotes).
struct Attribute {
  std::string name;
  std::size_t value_begin = 0, value_end = 0;
  std::size_t after = 0;  ///< one past the closing quote
};

// A start tag: its name, attributes, where it opens ('<'), where its '>' (or "/>") starts, and
// whether it closes itself.
struct Tag {
  std::string name;
  std::vector<Attribute> attributes;
  std::size_t open = 0, close = 0;
  bool empty = false;
  const Attribute* find(const std::string& attribute) const {
    for (const Attribute& a : attributes)
      if (a.name == attribute) return &a;
    return nullptr;
  }
};

// The joints the edit may touch: each root <joint>'s start tag and its first <origin> child.
struct JointTags {
  Tag joint;
  bool has_origin = false;
  Tag origin;
};

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

// Decodes the five predefined entities (tinyxml2 does so for the names it compares).
std::string decoded(const std::string& raw) {
  static const std::pair<const char*, char> kEntities[] = {
      {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (std::size_t i = 0; i < raw.size();) {
    bool matched = false;
    for (const auto& [entity, c] : kEntities) {
      const std::string e(entity);
      if (raw.compare(i, e.size(), e) == 0) {
        out += c;
        i += e.size();
        matched = true;
        break;
      }
    }
    if (!matched) out += raw[i++];
  }
  return out;
}

class Scanner {
 public:
  Scanner(const std::string& text, const std::string& source) : text_(text), source_(source) {}

  std::map<std::string, JointTags> joints() {
    std::map<std::string, JointTags> out;
    std::vector<std::string> stack;
    JointTags* current = nullptr;
    std::size_t joint_depth = 0;
    for (std::size_t i = text_.find('<'); i != std::string::npos; i = text_.find('<', i)) {
      if (skipMarkup(i)) continue;
      if (text_.compare(i, 2, "</") == 0) {
        i = endOf(i, ">") + 1;
        if (!stack.empty()) stack.pop_back();
        if (current && stack.size() < joint_depth) current = nullptr;
        continue;
      }
      const Tag tag = startTag(i);
      i = tag.close + (tag.empty ? 2 : 1);
      if (stack.size() == 1 && tag.name == "joint") {
        const Attribute* name = tag.find("name");
        if (name && !tag.empty) {
          const std::string key =
              decoded(text_.substr(name->value_begin, name->value_end - name->value_begin));
          current = &out.emplace(key, JointTags{tag, false, {}}).first->second;
          joint_depth = 2;
        }
      } else if (current && stack.size() == 2 && tag.name == "origin" && !current->has_origin) {
        current->has_origin = true;
        current->origin = tag;
      }
      if (!tag.empty) stack.push_back(tag.name);
    }
    return out;
  }

 private:
  [[noreturn]] void fail(std::size_t at, const std::string& message) const {
    const auto line = std::count(text_.begin(), text_.begin() + static_cast<long>(at), '\n') + 1;
    throw InputError(source_, "line " + std::to_string(line), message);
  }

  std::size_t endOf(std::size_t from, const char* terminator) const {
    const std::size_t end = text_.find(terminator, from);
    if (end == std::string::npos)
      fail(from, std::string("unterminated markup (no \"") + terminator + "\")");
    return end;
  }

  // Comments, CDATA, processing instructions and declarations: skipped, `i` past them.
  bool skipMarkup(std::size_t& i) const {
    if (text_.compare(i, 4, "<!--") == 0) {
      i = endOf(i + 4, "-->") + 3;
    } else if (text_.compare(i, 9, "<![CDATA[") == 0) {
      i = endOf(i + 9, "]]>") + 3;
    } else if (text_.compare(i, 2, "<?") == 0) {
      i = endOf(i + 2, "?>") + 2;
    } else if (text_.compare(i, 2, "<!") == 0) {  // DOCTYPE, with an internal subset in [...]
      int brackets = 0;
      std::size_t j = i + 2;
      for (; j < text_.size(); ++j) {
        if (text_[j] == '[') ++brackets;
        if (text_[j] == ']') --brackets;
        if (text_[j] == '>' && brackets <= 0) break;
      }
      if (j >= text_.size()) fail(i, "unterminated declaration");
      i = j + 1;
    } else {
      return false;
    }
    return true;
  }

  Tag startTag(std::size_t open) const {
    Tag tag;
    tag.open = open;
    std::size_t j = open + 1;
    while (j < text_.size() && !isSpace(text_[j]) && text_[j] != '>' && text_[j] != '/') ++j;
    tag.name = text_.substr(open + 1, j - open - 1);
    for (;;) {
      while (j < text_.size() && isSpace(text_[j])) ++j;
      if (j >= text_.size()) fail(open, "unterminated tag <" + tag.name + ">");
      if (text_[j] == '>' || text_.compare(j, 2, "/>") == 0) {
        tag.close = j;
        tag.empty = text_[j] == '/';
        return tag;
      }
      Attribute a;
      const std::size_t name_begin = j;
      while (j < text_.size() && !isSpace(text_[j]) && text_[j] != '=') ++j;
      a.name = text_.substr(name_begin, j - name_begin);
      while (j < text_.size() && isSpace(text_[j])) ++j;
      if (j >= text_.size() || text_[j] != '=') fail(open, "attribute without a value");
      ++j;
      while (j < text_.size() && isSpace(text_[j])) ++j;
      if (j >= text_.size() || (text_[j] != '"' && text_[j] != '\'')) {
        fail(open, "attribute value without quotes");
      }
      const char quote = text_[j];
      a.value_begin = j + 1;
      a.value_end = text_.find(quote, a.value_begin);
      if (a.value_end == std::string::npos) fail(open, "unterminated attribute value");
      a.after = a.value_end + 1;
      j = a.after;
      tag.attributes.push_back(a);
    }
  }

  const std::string& text_;
  const std::string& source_;
};

// The three numbers of an origin attribute's text, or false.
bool threeNumbers(const std::string& text, Eigen::Vector3d& v) {
  std::istringstream in(text);
  std::string token;
  int n = 0;
  while (in >> token) {
    if (n == 3) return false;
    char* end = nullptr;
    v[n++] = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) return false;
  }
  return n == 3;
}

bool same(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return ((a - b).array().abs() <= 1e-14).all();
}

std::string tripleText(const Eigen::Vector3d& v) {
  return shortestNumber(v[0]) + " " + shortestNumber(v[1]) + " " + shortestNumber(v[2]);
}

struct Replacement {
  std::size_t begin, end;
  std::string text;
};

// The indentation of the line `at` lies on.
std::string indentationAt(const std::string& text, std::size_t at) {
  const std::size_t line = text.rfind('\n', at);
  const std::size_t begin = line == std::string::npos ? 0 : line + 1;
  std::size_t end = begin;
  while (end < at && (text[end] == ' ' || text[end] == '\t')) ++end;
  return text.substr(begin, end - begin);
}

void editOrigin(const std::string& text, const JointTags& tags, const OriginEdit& edit,
                const std::string& source, std::vector<Replacement>& out) {
  const std::pair<const char*, const Eigen::Vector3d*> values[] = {{"xyz", &edit.xyz_m},
                                                                   {"rpy", &edit.rpy}};
  if (!tags.has_origin) {
    if (edit.xyz_m.isZero(0.0) && edit.rpy.isZero(0.0)) return;
    const std::string newline = text.find("\r\n") != std::string::npos ? "\r\n" : "\n";
    const std::string line = newline + indentationAt(text, tags.joint.open) + "  <origin xyz=\"" +
                             tripleText(edit.xyz_m) + "\" rpy=\"" + tripleText(edit.rpy) + "\"/>";
    out.push_back({tags.joint.close + 1, tags.joint.close + 1, line});
    return;
  }
  const Tag& origin = tags.origin;
  std::size_t insert_at = origin.attributes.empty() ? origin.open + 7 : 0;
  for (const Attribute& a : origin.attributes) insert_at = std::max(insert_at, a.after);
  for (const auto& [name, value] : values) {
    const Attribute* a = origin.find(name);
    if (!a) {
      if (!value->isZero(0.0))
        out.push_back(
            {insert_at, insert_at, std::string(" ") + name + "=\"" + tripleText(*value) + "\""});
      continue;
    }
    Eigen::Vector3d old;
    if (!threeNumbers(text.substr(a->value_begin, a->value_end - a->value_begin), old)) {
      throw InputError(source, "joint \"" + edit.joint + "\"",
                       std::string("<origin ") + name + "> needs 3 numbers");
    }
    if (!same(old, *value)) out.push_back({a->value_begin, a->value_end, tripleText(*value)});
  }
}

}  // namespace

std::string shortestNumber(double value) {
  if (value == 0.0) return "0";  // -0 too
  char buffer[32];
  const auto [end, error] = std::to_chars(buffer, buffer + sizeof buffer, value);
  (void)error;
  return std::string(buffer, end);
}

std::string editJointOrigins(const std::string& text, const std::vector<OriginEdit>& edits,
                             const std::string& source) {
  const std::map<std::string, JointTags> joints = Scanner(text, source).joints();
  std::vector<Replacement> replacements;
  for (const OriginEdit& edit : edits) {
    const auto it = joints.find(edit.joint);
    if (it == joints.end())
      throw InputError(source, "", "joint \"" + edit.joint + "\" not found in the XML");
    editOrigin(text, it->second, edit, source, replacements);
  }
  // Last first; of two insertions at one place the later pushed goes in first (ends up after).
  std::reverse(replacements.begin(), replacements.end());
  std::stable_sort(replacements.begin(), replacements.end(),
                   [](const Replacement& a, const Replacement& b) { return a.begin > b.begin; });
  std::string out = text;
  for (const Replacement& r : replacements) out.replace(r.begin, r.end - r.begin, r.text);
  return out;
}

}  // namespace artcal
