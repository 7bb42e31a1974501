// The HTML report and its SVG layer (issue 5): every SVG (and the page itself) is well-formed
// XML, every number shown equals the one `artcal evaluate --json` prints, a 1000-placement plan
// stays under 2 MB, and the page fetches nothing.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "artcal/estimation/error_functions.hpp"
#include "artcal/internal.hpp"
#include "artcal/model/cartesian.hpp"
#include "artcal/report/cartesian_report.hpp"
#include "artcal/report/location_errors.hpp"
#include "artcal/report/text_format.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace report_test {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// A small, strict XML well-formedness checker: balanced and properly nested tags, one root
// element, attributes quoted and not repeated, & only as a known entity, no raw < or > in text
// or attribute values. Allows an XML declaration, a DOCTYPE and comments before the root.

class XmlChecker {
 public:
  explicit XmlChecker(std::string_view text) : s_(text) {}

  /// The first fault found, or std::nullopt when the document is well-formed.
  std::optional<std::string> check() {
    skipProlog();
    if (fault_) return fault_;
    int roots = 0;
    while (pos_ < s_.size() && !fault_) {
      if (s_[pos_] == '<') {
        if (s_.compare(pos_, 4, "<!--") == 0) {
          skipComment();
        } else if (s_.compare(pos_, 2, "</") == 0) {
          closeTag();
        } else {
          if (stack_.empty() && ++roots > 1) return fail("a second root element");
          openTag();
        }
      } else {
        text();
      }
    }
    if (fault_) return fault_;
    if (!stack_.empty()) return fail("unclosed <" + stack_.back() + ">");
    if (roots == 0) return fail("no root element");
    return std::nullopt;
  }

 private:
  std::optional<std::string> fail(const std::string& what) {
    if (!fault_) fault_ = what + " at offset " + std::to_string(pos_);
    pos_ = s_.size();
    return fault_;
  }

  static bool nameStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
  static bool nameChar(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == ':';
  }

  void skipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }

  void skipProlog() {
    for (;;) {
      skipSpace();
      if (s_.compare(pos_, 5, "<?xml") == 0) {
        const auto end = s_.find("?>", pos_);
        if (end == std::string_view::npos) return void(fail("unterminated XML declaration"));
        pos_ = end + 2;
      } else if (s_.compare(pos_, 9, "<!DOCTYPE") == 0) {
        const auto end = s_.find('>', pos_);
        if (end == std::string_view::npos) return void(fail("unterminated DOCTYPE"));
        pos_ = end + 1;
      } else if (s_.compare(pos_, 4, "<!--") == 0) {
        skipComment();
      } else {
        return;
      }
    }
  }

  void skipComment() {
    const auto end = s_.find("-->", pos_ + 4);
    if (end == std::string_view::npos) return void(fail("unterminated comment"));
    pos_ = end + 3;
  }

  std::string name() {
    const std::size_t start = pos_;
    if (pos_ >= s_.size() || !nameStart(s_[pos_])) {
      fail("expected a name");
      return {};
    }
    while (pos_ < s_.size() && nameChar(s_[pos_])) ++pos_;
    return std::string(s_.substr(start, pos_ - start));
  }

  // An entity reference starting at s_[pos_] == '&'.
  void entity() {
    static const std::regex kEntity("&(amp|lt|gt|quot|apos|#[0-9]+|#x[0-9a-fA-F]+);");
    const auto end = s_.find(';', pos_);
    if (end == std::string_view::npos || end - pos_ > 12) return void(fail("a raw &"));
    const std::string candidate(s_.substr(pos_, end - pos_ + 1));
    if (!std::regex_match(candidate, kEntity)) return void(fail("unknown entity " + candidate));
    pos_ = end + 1;
  }

  void text() {
    while (pos_ < s_.size() && s_[pos_] != '<' && !fault_) {
      if (s_[pos_] == '&') {
        entity();
      } else if (s_[pos_] == '>') {
        fail("a raw > in text");
      } else {
        ++pos_;
      }
    }
    if (stack_.empty() && !fault_) {
      // Only white space may sit outside the root element (checked loosely by the caller).
    }
  }

  void attributeValue() {
    if (pos_ >= s_.size() || (s_[pos_] != '"' && s_[pos_] != '\'')) {
      return void(fail("an unquoted attribute value"));
    }
    const char quote = s_[pos_++];
    while (pos_ < s_.size() && s_[pos_] != quote && !fault_) {
      if (s_[pos_] == '<' || s_[pos_] == '>') return void(fail("a raw < or > in an attribute"));
      if (s_[pos_] == '&') {
        entity();
      } else {
        ++pos_;
      }
    }
    if (pos_ >= s_.size()) return void(fail("an unterminated attribute value"));
    ++pos_;
  }

  void openTag() {
    ++pos_;  // <
    const std::string tag = name();
    std::set<std::string> seen;
    while (!fault_) {
      const std::size_t before = pos_;
      skipSpace();
      if (pos_ >= s_.size()) return void(fail("an unterminated tag <" + tag + ">"));
      if (s_.compare(pos_, 2, "/>") == 0) {
        pos_ += 2;
        return;
      }
      if (s_[pos_] == '>') {
        ++pos_;
        stack_.push_back(tag);
        return;
      }
      if (pos_ == before) return void(fail("no space before an attribute of <" + tag + ">"));
      const std::string attribute = name();
      if (fault_) return;
      if (!seen.insert(attribute).second) return void(fail("a repeated attribute " + attribute));
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != '=') return void(fail("attribute without a value"));
      ++pos_;
      skipSpace();
      attributeValue();
    }
  }

  void closeTag() {
    pos_ += 2;
    const std::string tag = name();
    skipSpace();
    if (pos_ >= s_.size() || s_[pos_] != '>') return void(fail("an unterminated end tag"));
    ++pos_;
    if (stack_.empty() || stack_.back() != tag) {
      return void(fail("</" + tag + "> does not close " +
                       (stack_.empty() ? std::string("anything") : "<" + stack_.back() + ">")));
    }
    stack_.pop_back();
  }

  std::string_view s_;
  std::size_t pos_ = 0;
  std::vector<std::string> stack_;
  std::optional<std::string> fault_;
};

std::optional<std::string> xmlFault(std::string_view text) {
  return XmlChecker(text).check();
}

TEST(XmlChecker, AcceptsWellFormedDocuments) {
  EXPECT_EQ(xmlFault("<a/>"), std::nullopt);
  EXPECT_EQ(xmlFault("<?xml version=\"1.0\"?>\n<svg x='1' y=\"2\"><g><t>a &amp; b &#181;</t></g>"
                     "<!-- note --></svg>\n"),
            std::nullopt);
  EXPECT_EQ(xmlFault("<!DOCTYPE html>\n<html><meta charset=\"utf-8\"/></html>"), std::nullopt);
}

TEST(XmlChecker, RejectsEachKindOfFault) {
  EXPECT_NE(xmlFault("<a><b></a></b>"), std::nullopt);           // misnested
  EXPECT_NE(xmlFault("<a><b></b>"), std::nullopt);               // unclosed
  EXPECT_NE(xmlFault("<a></a><b></b>"), std::nullopt);           // two roots
  EXPECT_NE(xmlFault("<a x=1></a>"), std::nullopt);              // unquoted attribute
  EXPECT_NE(xmlFault("<a x=\"1\" x=\"2\"></a>"), std::nullopt);  // repeated attribute
  EXPECT_NE(xmlFault("<a x=\"1\"y=\"2\"></a>"), std::nullopt);   // no space between
  EXPECT_NE(xmlFault("<a>R&D</a>"), std::nullopt);               // raw &
  EXPECT_NE(xmlFault("<a>1 < 2</a>"), std::nullopt);             // raw <
  EXPECT_NE(xmlFault("<a>2 > 1</a>"), std::nullopt);             // raw >
  EXPECT_NE(xmlFault("<a x=\"<\"></a>"), std::nullopt);          // < in attribute
  EXPECT_NE(xmlFault("<a>&nbsp;</a>"), std::nullopt);            // not an XML entity
  EXPECT_NE(xmlFault(""), std::nullopt);                         // no root
}

// ---------------------------------------------------------------------------------------------
// The SVG layer

TEST(Svg, EscapesEveryMarkupCharacter) {
  EXPECT_EQ(svg::escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
  EXPECT_EQ(svg::escape("l1 + l2"), "l1 + l2");
}

TEST(Svg, TicksAreRoundStepsCoveringTheRange) {
  EXPECT_EQ(svg::niceTicks(0.0, 10.0, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  EXPECT_EQ(svg::niceTicks(-0.3, 0.3, 6),
            (std::vector<double>{-0.3, -0.2, -0.1, 0, 0.1, 0.2, 0.3}));
  const auto ticks = svg::niceTicks(37.0, 263.0, 6);
  ASSERT_FALSE(ticks.empty());
  EXPECT_DOUBLE_EQ(ticks.front(), 50.0);
  EXPECT_DOUBLE_EQ(ticks.back(), 250.0);
  EXPECT_DOUBLE_EQ(ticks[1] - ticks[0], 50.0);
  EXPECT_TRUE(svg::niceTicks(1.0, 1.0).empty());
  EXPECT_EQ(svg::tickLabel(0.5, 0.1), "0.5");
  EXPECT_EQ(svg::tickLabel(-200.0, 100.0), "-200");
  EXPECT_EQ(svg::tickLabel(2.25, 0.05), "2.25");
  EXPECT_EQ(svg::tickLabel(-1e-17, 0.1), "0.0");
}

double luminance(const std::string& hex) {
  const auto channel = [&](int i) { return std::stoi(hex.substr(1 + 2 * i, 2), nullptr, 16); };
  return 0.2126 * channel(0) + 0.7152 * channel(1) + 0.0722 * channel(2);
}

TEST(Svg, SequentialMapSurvivesGreyscale) {
  EXPECT_EQ(svg::viridis(0.0), "#440154");
  EXPECT_EQ(svg::viridis(1.0), "#fde725");
  EXPECT_EQ(svg::viridis(-3.0), svg::viridis(0.0));
  double previous = -1.0;
  for (int k = 0; k <= 100; ++k) {  // greyscale keeps the order: luminance strictly rises
    const double l = luminance(svg::viridis(k / 100.0));
    EXPECT_GT(l, previous) << k;
    previous = l;
  }
}

TEST(Svg, PlotWithHostileTextIsWellFormed) {
  svg::Plot plot("p<1>", "S & \"friends\" <b>", "x < 1 / mm", "y > 0 / 'um'");
  plot.polyline({{0, 0}, {1, 2}, {2, 1}}, {}, "a & b");
  svg::Style dashed;
  dashed.dash = svg::Dash::Dashed;
  plot.polyline({{0, 1}, {2, 1}}, dashed, "</svg>");
  plot.circle({1, 1}, 0.5, {}, "circle");
  for (const auto shape : {svg::Shape::Circle, svg::Shape::Square, svg::Shape::Triangle,
                           svg::Shape::Diamond, svg::Shape::Cross}) {
    plot.marker({0.5, 0.5}, shape, 6, {}, "m", {{"data-field", "/a&b"}}, "<tip>");
  }
  plot.cell({0, 0}, {0.2, 0.2}, svg::viridis(0.3));
  plot.label({1.5, 1.5}, "R&D <x>");
  plot.setColourBar(0, 3, "S / um & more");
  const std::string out = plot.render();
  EXPECT_EQ(xmlFault(out), std::nullopt) << out;
  EXPECT_NE(out.find("S &amp; &quot;friends&quot; &lt;b&gt;"), std::string::npos);
  EXPECT_NE(out.find("stroke-dasharray"), std::string::npos);  // the dashed series differs
  EXPECT_EQ(out.find("<script"), std::string::npos);
}

TEST(Svg, HeatMapCellsCarryTheirValues) {
  Eigen::Matrix3d m;
  m << 1.0, -0.25, 0.75, -0.25, 1.0, 0.0, 0.75, 0.0, 1.0;
  const std::string out =
      svg::matrixHeatMap("h", "corr", {"a<", "b&", "c"}, m, -1, 1, "/correlation");
  EXPECT_EQ(xmlFault(out), std::nullopt) << out;
  // Every cell carries its value; only |r| >= 0.5 off the diagonal is printed (issue 14).
  EXPECT_NE(out.find("data-field=\"/correlation/0/1\" data-value=\"-0.25\""), std::string::npos);
  EXPECT_NE(out.find("data-field=\"/correlation/1/1\" data-value=\"1\""), std::string::npos);
  EXPECT_EQ(out.find(">-0.25<"), std::string::npos);
  EXPECT_EQ(out.find(">1.00<"), std::string::npos);
  EXPECT_NE(out.find(">0.75<"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The command line

struct CliRun {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class ReportCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("artcal-test-report-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CliRun run(const std::string& arguments) const {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command = std::string("\"") + ARTCAL_CLI + "\" " + arguments + " >\"" +
                                out.string() + "\" 2>\"" + err.string() + "\"";
    const int raw = std::system(command.c_str());
    CliRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }

  static std::string data(const std::string& name) { return test_support::testDataFile(name); }

  /// The readings of `plan` simulated (seed 4) with the parameters `truth` (a JSON object of name
  /// and value), reported: the report's HTML and calibrate --json of the same readings.
  std::pair<std::string, json> reportOfSimulated(const std::string& plan,
                                                 const std::string& truth) const {
    const fs::path truth_file = dir_ / "truth.json", simulated = dir_ / "sim.json",
                   html_path = dir_ / "r.html";
    std::ofstream(truth_file) << R"({"parameters": )" << truth << "}";
    EXPECT_EQ(run("simulate \"" + plan + "\" --truth \"" + truth_file.string() +
                  "\" --seed 4 -o \"" + simulated.string() + "\"")
                  .status,
              0);
    EXPECT_EQ(run("report \"" + simulated.string() + "\" -o \"" + html_path.string() + "\"").status,
              0);
    return {slurp(html_path),
            json::parse(run("calibrate --json \"" + simulated.string() + "\"").out)};
  }

  /// verify --json of `held` with the nominal machine and with the machine calibrate
  /// --write-machine writes to `cal` from `trained`.
  std::pair<json, json> verifiedNominalAndCalibrated(const fs::path& trained, const fs::path& held,
                                                     const fs::path& cal) const {
    EXPECT_EQ(run("calibrate \"" + trained.string() + "\" --write-machine \"" + cal.string() + "\"")
                  .status,
              0);
    return {
        json::parse(run("verify --json \"" + held.string() + "\"").out),
        json::parse(
            run("verify --json \"" + held.string() + "\" --machine \"" + cal.string() + "\"").out)};
  }

  fs::path dir_;
};

/// Every <svg>...</svg> element of a page.
std::vector<std::string> inlineSvgs(const std::string& html) {
  std::vector<std::string> out;
  for (std::size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at)) {
    const std::size_t end = html.find("</svg>", at);
    if (end == std::string::npos) break;
    out.push_back(html.substr(at, end + 6 - at));
    at = end;
  }
  return out;
}

struct Shown {
  std::string pointer, value, text;
};

/// Every element carrying data-field / data-value, with the text it shows (up to the next tag).
std::vector<Shown> shownNumbers(const std::string& html) {
  static const std::regex kField("data-field=\"([^\"]*)\" data-value=\"([^\"]*)\"[^>]*>([^<]*)");
  std::vector<Shown> out;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), kField);
       it != std::sregex_iterator(); ++it) {
    out.push_back({(*it)[1], (*it)[2], (*it)[3]});
  }
  return out;
}

/// The report's numbers against `evaluate --json` for the same plan: every data-field exists in
/// the evaluation and holds exactly the value shown. Fields under /calibration are looked up in
/// `calibrate --json` instead (when given).
std::set<std::string> expectNumbersMatchEvaluate(const std::string& html, const json& evaluated,
                                                 const json* calibrated = nullptr) {
  std::set<std::string> pointers;
  const std::string prefix = "/calibration/";
  for (const Shown& s : shownNumbers(html)) {
    pointers.insert(s.pointer);
    const bool calibration = s.pointer.rfind(prefix, 0) == 0;
    if (calibration && !calibrated) {
      ADD_FAILURE() << s.pointer << ": a calibration number in a report without calibration";
      continue;
    }
    const json& source = calibration ? *calibrated : evaluated;
    const json::json_pointer pointer(calibration ? s.pointer.substr(prefix.size() - 1) : s.pointer);
    if (!source.contains(pointer)) {
      ADD_FAILURE() << s.pointer << " is not in the command's --json";
      continue;
    }
    const json& expected = source.at(pointer);
    if (expected.is_number()) {
      EXPECT_EQ(std::stod(s.value), expected.get<double>()) << s.pointer;
    } else {
      EXPECT_EQ(s.value, expected.dump()) << s.pointer;
    }
  }
  return pointers;
}

/// `svg_count` figures before the operator's procedure (procedure.hpp), whose drawings (one or
/// three per placement, none beyond 60 placements) follow; every SVG well-formed.
void expectWellFormed(const std::string& html, std::size_t svg_count) {
  EXPECT_EQ(xmlFault(html), std::nullopt);
  const std::size_t procedure = html.find("<h2>Procedure</h2>");
  ASSERT_NE(procedure, std::string::npos);
  EXPECT_EQ(inlineSvgs(html.substr(0, procedure)).size(), svg_count);
  for (const std::string& s : inlineSvgs(html)) {
    EXPECT_EQ(xmlFault(s), std::nullopt) << s.substr(0, 200);
  }
}

/// Self-contained: nothing that a browser would fetch or run.
void expectSelfContained(const std::string& html) {
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_EQ(html.find("href="), std::string::npos);
  EXPECT_EQ(html.find("@import"), std::string::npos);
  EXPECT_EQ(html.find("@font-face"), std::string::npos);
  std::string rest = html;
  for (std::size_t at; (at = rest.find("http://www.w3.org/2000/svg")) != std::string::npos;) {
    rest.erase(at, 26);
  }
  EXPECT_EQ(rest.find("http"), std::string::npos);
  EXPECT_EQ(rest.find("url("), rest.find("url(#"));  // only local references (clip paths)
}

TEST_F(ReportCli, Planar2RNumbersEqualEvaluateJson) {
  const fs::path html_path = dir_ / "r.html", svg_dir = dir_ / "svg";
  const CliRun r = run("report \"" + data("ref-2r-5bars.json") + "\" -o \"" + html_path.string() +
                       "\" --svg \"" + svg_dir.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const CliRun ev = run("evaluate --json \"" + data("ref-2r-5bars.json") + "\"");
  ASSERT_EQ(ev.status, 0) << ev.err;
  const json evaluated = json::parse(ev.out);
  const std::string html = slurp(html_path);
  expectWellFormed(html, 4);  // layout, profile, map, correlation
  expectSelfContained(html);

  const std::set<std::string> shown = expectNumbersMatchEvaluate(html, evaluated);
  for (std::size_t k = 0; k < evaluated["parameters"].size(); ++k) {
    EXPECT_TRUE(shown.count("/parameters/" + std::to_string(k) + "/u")) << k;
    EXPECT_TRUE(shown.count("/parameters/" + std::to_string(k) + "/nominal")) << k;
  }
  for (const char* p :
       {"/tip/worst/total", "/tip/worst/kinematic", "/tip/worst/encoder", "/tip/mean", "/tip/rms",
        "/tip/worst/joints/1", "/correlation/0/2", "/counting/N_b", "/rank/deficiency"}) {
    EXPECT_TRUE(shown.count(p)) << p;
  }
  ASSERT_EQ(evaluated["profile"].size(), 21u);
  for (std::size_t k = 0; k < 21; ++k) {
    for (const char* key : {"total", "kinematic", "encoder"}) {
      EXPECT_TRUE(shown.count("/profile/" + std::to_string(k) + "/" + key)) << k << key;
    }
  }
  // The text a reader sees is the JSON value in the unit of its column: u of l1 in um.
  for (const Shown& s : shownNumbers(html)) {
    if (s.pointer == "/parameters/0/u") {
      EXPECT_NEAR(std::stod(s.text), evaluated["parameters"][0]["u"].get<double>() * 1e3, 5e-4);
    }
    if (s.pointer == "/tip/worst/total" && !s.text.empty()) {
      EXPECT_NEAR(std::stod(s.text), evaluated["tip"]["worst"]["total"].get<double>() * 1e3, 5e-4);
    }
  }

  // Greyscale-safe curves: S solid, S_m dashed, S_q dotted (seed Fig. 6).
  const std::string profile = slurp(svg_dir / "tip-profile.svg");
  for (const char* dash : {"8 4", "1.5 3"}) {
    const std::regex curve(std::string("<polyline[^>]*stroke-dasharray=\"") + dash + "\"");
    EXPECT_EQ(std::distance(std::sregex_iterator(profile.begin(), profile.end(), curve),
                            std::sregex_iterator()),
              1)
        << dash;
  }
  const std::regex any_curve("<polyline[^>]*/>");
  EXPECT_EQ(std::distance(std::sregex_iterator(profile.begin(), profile.end(), any_curve),
                          std::sregex_iterator()),
            3);

  // The planar map is drawn from the profile (S depends on the reach alone): every cell of the
  // 48 x 48 grid over the reach disc whose centre lies within the profile's reach, no hole.
  {
    double r_min = 1e300, r_max = 0.0;
    for (const json& row : evaluated["profile"]) {
      r_min = std::min(r_min, row["reach"].get<double>());
      r_max = std::max(r_max, row["reach"].get<double>());
    }
    int inside = 0;
    for (int i = 0; i < 48; ++i) {
      for (int j = 0; j < 48; ++j) {
        const double r =
            std::hypot(-r_max + (i + 0.5) * 2 * r_max / 48, -r_max + (j + 0.5) * 2 * r_max / 48);
        inside += r >= r_min && r <= r_max;
      }
    }
    const std::string map = slurp(svg_dir / "tip-map.svg");
    std::size_t cells = 0;
    for (std::size_t at = 0; (at = map.find("class=\"map-cell\"", at)) != std::string::npos; ++at)
      ++cells;
    EXPECT_GT(inside, 1000);
    EXPECT_EQ(cells, static_cast<std::size_t>(inside));
  }

  // --svg: the same figures, one well-formed file each.
  for (const char* name : {"layout", "tip-profile", "tip-map", "correlation"}) {
    const fs::path file = svg_dir / (std::string(name) + ".svg");
    ASSERT_TRUE(fs::exists(file)) << name;
    const std::string text = slurp(file);
    EXPECT_EQ(xmlFault(text), std::nullopt) << name;
    EXPECT_NE(html.find(text.substr(text.find("<svg"))), std::string::npos) << name;
  }
}

TEST_F(ReportCli, SpatialArmHasPlanAndSideViewsAndTheWorstPoint) {
  const fs::path html_path = dir_ / "r.html";
  const CliRun r = run("report \"" + data("ref-aacmm-3bars-3postures.json") + "\" -o \"" +
                       html_path.string() + "\" --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json summary = json::parse(r.out);
  std::vector<std::string> names;
  for (const auto& f : summary["figures"]) names.push_back(f["name"]);
  EXPECT_EQ(names, (std::vector<std::string>{"layout", "layout-side", "tip-map", "tip-map-side",
                                             "correlation"}));
  const CliRun ev = run("evaluate --json \"" + data("ref-aacmm-3bars-3postures.json") + "\"");
  const json evaluated = json::parse(ev.out);
  const std::string html = slurp(html_path);
  EXPECT_EQ(summary["bytes"].get<std::size_t>(), html.size());
  expectWellFormed(html, 5);
  expectSelfContained(html);
  const std::set<std::string> shown = expectNumbersMatchEvaluate(html, evaluated);
  EXPECT_TRUE(shown.count("/correlation/20/20"));
  EXPECT_TRUE(shown.count("/parameters/20/u"));
  EXPECT_EQ(html.find("/profile/"), std::string::npos);  // no reach profile for a serial arm
  // The worst point is marked in both views of the map.
  std::size_t worst_marks = 0;
  for (const Shown& s : shownNumbers(html)) worst_marks += s.pointer == "/tip/worst/total";
  EXPECT_EQ(worst_marks, 3u);  // table cell + two map views
}

// The real Panda readings: the calibration section names calibrate's gross errors with the CSV
// file and row each came from (four balls not seated, |z| 10-14; docs/panda.md).
TEST_F(ReportCli, CalibrationSectionNamesTheGrossErrorsWithTheirCsvRows) {
  const fs::path html_path = dir_ / "panda.html";
  const CliRun r = run("report \"" + test_support::planFile("panda-8positions.json") +
                       "\" --calibrate -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string html = slurp(html_path);
  expectWellFormed(html, 6);  // the 5 of a 3-D plan and the residual plot
  EXPECT_NE(html.find("<strong>4 gross errors</strong>"), std::string::npos);
  for (const char* where : {"front_left/hole_1.csv row 22", "front_left/hole_1.csv row 23",
                            "front_right/hole_0.csv row 15", "back_left/hole_1.csv row 31"})
    EXPECT_NE(html.find(where), std::string::npos) << where;
}

TEST_F(ReportCli, TheWorkspaceMapsWorstIsTheEvaluatorsWorst) {
  // The map colours each configuration by S from TipEvaluator with the evaluator's V_p; its
  // largest value must be the evaluator's worst.
  const Plan plan = loadPlan(data("ref-aacmm-3bars-3postures.json"));
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.identifiable());
  const TipEvaluator tips(plan.machine, plan.noise, ev.workspace);
  Eigen::VectorXd S_m2;
  tips.kinematicVariance(ev.covariance->V, S_m2);
  const Eigen::VectorXd S = (S_m2 + tips.encoderVariance()).cwiseSqrt();
  Eigen::Index worst = 0;
  S.maxCoeff(&worst);
  EXPECT_EQ(worst, ev.tip->worst_index);
  EXPECT_NEAR(S[worst], ev.tip->worst.total, 1e-12 * ev.tip->worst.total);

  // The report's own map (report code, drawn from its own S per configuration): the one cell in
  // the top colour of the scale is where the diamond marks the evaluator's worst configuration,
  // and the diamond carries S[worst] computed above.
  const fs::path svg_dir = dir_ / "svg";
  const CliRun r = run("report \"" + data("ref-aacmm-3bars-3postures.json") + "\" -o \"" +
                       (dir_ / "r.html").string() + "\" --svg \"" + svg_dir.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* view : {"tip-map.svg", "tip-map-side.svg"}) {
    SCOPED_TRACE(view);
    const std::string map = slurp(svg_dir / view);
    const std::regex top_cell(
        "<rect x=\"([-0-9.]+)\" y=\"([-0-9.]+)\" width=\"([0-9.]+)\" "
        "height=\"([0-9.]+)\" fill=\"" +
        svg::viridis(1.0) + "\" class=\"map-cell\"/>");
    std::vector<std::array<double, 4>> cells;
    for (auto it = std::sregex_iterator(map.begin(), map.end(), top_cell);
         it != std::sregex_iterator(); ++it) {
      cells.push_back(
          {std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4])});
    }
    ASSERT_EQ(cells.size(), 1u);
    const std::regex diamond(
        "data-field=\"/tip/worst/total\" data-value=\"([^\"]+)\"><title>[^<]*</title>"
        "<polygon points=\"([-0-9.]+),[-0-9.]+ [-0-9.]+,([-0-9.]+) ");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(map, m, diamond));
    EXPECT_NEAR(std::stod(m[1]), S[worst], 1e-12 * S[worst]);
    const double centre_x = std::stod(m[2]), centre_y = std::stod(m[3]);
    const auto& [x, y, w, h] = cells.front();
    EXPECT_GE(centre_x, x - 0.1);
    EXPECT_LE(centre_x, x + w + 0.1);
    EXPECT_GE(centre_y, y - 0.1);
    EXPECT_LE(centre_y, y + h + 0.1);
  }
}

// S_m under the um header: the report's cells of S_m, S_q and S (the worst configuration and
// the reach profile of a planar arm) read in um are 1000 times S_m, S_q and S in mm computed
// here: S_m^2 = tr(J_p V_p J_p^T) with J_p by central differences of the forward kinematics at
// the configuration's joints, S_q^2 = tr(J_q Sigma_q J_q^T) likewise (docs/method.md section 4).
TEST_F(ReportCli, TipCellsAreMicrometresOfAnIndependentTipUncertainty) {
  const std::string plan_path = data("ref-2r-5bars.json");
  const fs::path html_path = dir_ / "r.html";
  ASSERT_EQ(run("report \"" + plan_path + "\" -o \"" + html_path.string() + "\"").status, 0);
  const std::string html = slurp(html_path);
  const Plan plan = loadPlan(plan_path);
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.identifiable());
  const Machine& machine = plan.machine;
  auto tipAt = [&](const Eigen::VectorXd& q) {
    const int n = machine.calibratedCount();
    Eigen::MatrixXd J_p(machine.dimension(), n), J_q(machine.dimension(), machine.jointCount());
    Eigen::VectorXd plus, minus;
    for (int k = 0; k < n; ++k) {
      const double h = 1e-6;
      Eigen::VectorXd p = machine.nominal;
      p[machine.calibrated[static_cast<std::size_t>(k)]] += h;
      forwardOrThrow(*machine.mechanism, p, q, plus);
      p[machine.calibrated[static_cast<std::size_t>(k)]] -= 2 * h;
      forwardOrThrow(*machine.mechanism, p, q, minus);
      J_p.col(k) = (plus - minus) / (2 * h);
    }
    for (int i = 0; i < machine.jointCount(); ++i) {
      const double h = 1e-7;
      Eigen::VectorXd dq = q;
      dq[i] += h;
      forwardOrThrow(*machine.mechanism, machine.nominal, dq, plus);
      dq[i] -= 2 * h;
      forwardOrThrow(*machine.mechanism, machine.nominal, dq, minus);
      J_q.col(i) = (plus - minus) / (2 * h);
    }
    const double S_m = std::sqrt((J_p * ev.covariance->V * J_p.transpose()).trace());
    const double S_q = (J_q * plan.noise.encoder.asDiagonal()).norm();  // Sigma_q diagonal
    return std::array<double, 3>{S_m, S_q, std::hypot(S_m, S_q)};
  };
  const std::array<const char*, 3> keys = {"kinematic", "encoder", "total"};
  std::map<std::string, double> expected_mm;
  const std::array<double, 3> worst =
      tipAt(ev.workspace[static_cast<std::size_t>(ev.tip->worst_index)]);
  for (std::size_t c = 0; c < 3; ++c) expected_mm[std::string("/tip/worst/") + keys[c]] = worst[c];
  ASSERT_EQ(ev.profile.size(), 21u);
  for (std::size_t k = 0; k < ev.profile.size(); ++k) {
    // The profile's configurations at reach rho: t1 = 0, t2 = +-acos (law of cosines), both
    // elbow branches; the larger S is kept (tip.hpp, reachProfile).
    const double l1 = machine.nominal[0], l2 = machine.nominal[1], rho = ev.profile[k].reach;
    const double cosine = (rho * rho - l1 * l1 - l2 * l2) / (2 * l1 * l2);
    const double elbow = std::acos(std::clamp(cosine, -1.0, 1.0));
    std::array<double, 3> tip = {0.0, 0.0, 0.0};
    for (const double branch : {elbow, -elbow}) {
      Eigen::VectorXd q(2);
      q << 0.0, branch - machine.nominal[2];
      const std::array<double, 3> here = tipAt(q);
      if (here[2] > tip[2]) tip = here;
    }
    for (std::size_t c = 0; c < 3; ++c)
      expected_mm["/profile/" + std::to_string(k) + "/" + keys[c]] = tip[c];
  }
  std::size_t checked = 0;
  for (const Shown& s : shownNumbers(html)) {
    const auto it = expected_mm.find(s.pointer);
    if (it == expected_mm.end() || s.text.empty()) continue;
    EXPECT_NEAR(std::stod(s.text), it->second * 1e3, 5e-4 + 1e-6 * it->second * 1e3) << s.pointer;
    ++checked;
  }
  EXPECT_EQ(checked, expected_mm.size());
  // The columns say so.
  EXPECT_NE(html.find("<th>tip uncertainty (\xC2\xB5m)</th><th>S</th><th>S_m</th>"),
            std::string::npos);
  EXPECT_NE(html.find("<th>S_m (\xC2\xB5m)</th><th>S_q (\xC2\xB5m)</th><th>S (\xC2\xB5m)</th>"),
            std::string::npos);
}

TEST_F(ReportCli, NotIdentifiablePlanStillGetsAReportSayingSo) {
  const fs::path html_path = dir_ / "r.html";
  const CliRun r = run("report \"" + data("ref-2r-ring-degenerate.json") + "\" -o \"" +
                       html_path.string() + "\"");
  EXPECT_EQ(r.status, 1) << r.err;
  const CliRun ev = run("evaluate --json \"" + data("ref-2r-ring-degenerate.json") + "\"");
  const json evaluated = json::parse(ev.out);
  ASSERT_FALSE(evaluated["identifiable"].get<bool>());
  const std::string html = slurp(html_path);
  expectWellFormed(html, 1);  // the layout only
  EXPECT_NE(html.find("NOT IDENTIFIABLE"), std::string::npos);
  const std::set<std::string> shown = expectNumbersMatchEvaluate(html, evaluated);
  EXPECT_TRUE(shown.count("/rank/deficiency"));
  EXPECT_TRUE(shown.count("/parameters/0/u"));  // shown as a dash, value null
  const auto& combinations = evaluated["rank"]["combinations"];
  ASSERT_FALSE(combinations.empty());
  for (const auto& name : combinations[0]["parameters"]) {
    EXPECT_NE(html.find(name.get<std::string>() + " "), std::string::npos);
  }
  EXPECT_TRUE(shown.count("/rank/combinations/0/coefficients/0"));
}

TEST_F(ReportCli, OptimizedPlanShowsDesignAndPredictedBesideEvaluation) {
  json plan = json::parse(std::ifstream(data("ref-2r-5bars.json")));
  plan["design"] = {{"artifact", "bar80"},
                    {"placements", 5},
                    {"postures", 1},
                    {"region", {{"reach", {55, 245}}}},
                    {"criterion", "worst-tip"},
                    {"seed", 7},
                    {"starts", 16},
                    {"time_limit", 60}};
  plan["predicted"] = {
      {"tip", {{"worst", {{"total", 0.0123}}}}},
      {"optimization",
       {{"algorithm", "sbplx<&>"},
        {"criterion", "worst-tip"},
        {"unit", "mm"},
        {"random_initial", {{"median", 0.0208}, {"best", 0.0123}}},
        {"best_start", {{"initial", 0.0187}, {"exchanged", 0.0115}, {"refined", 0.01125}}},
        {"value", 0.01125}}}};
  const fs::path plan_path = dir_ / "optimized.json", html_path = dir_ / "r.html";
  std::ofstream(plan_path) << plan.dump(1);
  const CliRun r = run("report \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string html = slurp(html_path);
  expectWellFormed(html, 4);
  EXPECT_NE(html.find("<td>criterion</td><td>worst-tip</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>region/reach</td><td>[55,245]</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>tip/worst/total</td><td class=\"num\">0.0123</td>"), std::string::npos);
  // The search from the starting designs to the optimum, criterion in um.
  EXPECT_NE(html.find("sbplx&lt;&amp;&gt;"), std::string::npos);
  EXPECT_NE(html.find("<td>random starting designs, median</td><td class=\"num\">20.800</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<td>optimum written to the plan</td><td class=\"num\">11.250</td>"),
            std::string::npos);
  EXPECT_EQ(html.find("<td>optimization/"), std::string::npos);
  const CliRun ev = run("evaluate --json \"" + plan_path.string() + "\"");
  expectNumbersMatchEvaluate(html, json::parse(ev.out));
}

// The optimizer predicted a different parameter set (another order, one parameter gone since):
// each predicted parameter's row is named by the parameter and its unit and sits beside that
// parameter's figure evaluated now, found by name, not by its index in the array.
TEST_F(ReportCli, PredictedParametersMeetTheirEvaluationByName) {
  json plan = json::parse(std::ifstream(data("ref-2r-5bars.json")));
  plan["predicted"] = {{"tip", {{"worst", {{"total", 0.0123}}}}},
                       {"parameters",
                        {{{"name", "dt2"}, {"nominal", 0.5}, {"u", 0.0123}, {"unit", "deg"}},
                         {{"name", "l0"}, {"nominal", 1.0}, {"u", 0.7}, {"unit", "mm"}},
                         {{"name", "l1"}, {"nominal", 150.0}, {"u", 0.009}, {"unit", "mm"}}}}};
  const fs::path plan_path = dir_ / "optimized.json", html_path = dir_ / "r.html";
  std::ofstream(plan_path) << plan.dump(1);
  const CliRun r = run("report \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string html = slurp(html_path);
  const CliRun ev = run("evaluate --json \"" + plan_path.string() + "\"");
  ASSERT_EQ(ev.status, 0) << ev.err;
  const json evaluated = json::parse(ev.out);
  const auto indexOf = [&](const std::string& name) {
    const json& parameters = evaluated.at("parameters");
    for (std::size_t i = 0; i < parameters.size(); ++i)
      if (parameters[i].at("name") == name) return static_cast<int>(i);
    return -1;
  };
  ASSERT_EQ(indexOf("dt2"), 2);  // not the predicted block's index 0
  ASSERT_EQ(indexOf("l0"), -1);
  for (const auto& [name, unit, predicted] :
       {std::tuple<std::string, std::string, std::string>{"dt2", "deg", "0.0123"},
        {"l1", "mm", "0.009"}}) {
    const std::string row = "<td>parameters/" + name + "/u (" + unit + ")</td><td class=\"num\">" +
                            predicted + "</td><td class=\"num\" data-field=\"/parameters/" +
                            std::to_string(indexOf(name)) + "/u\"";
    EXPECT_NE(html.find(row), std::string::npos) << row;
  }
  EXPECT_NE(html.find("<td>parameters/l0/u (mm)</td><td class=\"num\">0.7</td><td></td>"),
            std::string::npos);
  EXPECT_EQ(html.find("<td>parameters/0/"), std::string::npos);  // no row labelled by index
  EXPECT_NE(html.find("<td>tip/worst/total</td><td class=\"num\">0.0123</td>"), std::string::npos);
  // Every number shown beside a prediction is the evaluation's at its data-field.
  expectNumbersMatchEvaluate(html, evaluated);
}

TEST_F(ReportCli, BadInputIsOneLineExitTwoAndNoFile) {
  json plan = json::parse(std::ifstream(data("ref-2r-5bars.json")));
  plan["placements"][1]["measurements"][0]["joints"] = {1.0, 2.0, 3.0};
  const fs::path plan_path = dir_ / "bad.json", html_path = dir_ / "r.html";
  std::ofstream(plan_path) << plan.dump(1);
  const CliRun r = run("report \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("/placements/1/measurements/0/joints"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_FALSE(fs::exists(html_path));
}

TEST_F(ReportCli, CalibrationResultAndFlaggedOutliersEqualCalibrateJson) {
  // One reading of ref-2r-calibrate spoilt by 0.1 deg on joint 2: the calibrator flags it.
  json plan = json::parse(std::ifstream(data("ref-2r-calibrate.json")));
  plan["placements"][3]["measurements"][1]["joints"][1] =
      plan["placements"][3]["measurements"][1]["joints"][1].get<double>() + 0.1;
  const fs::path plan_path = dir_ / "outlier.json", html_path = dir_ / "r.html";
  std::ofstream(plan_path) << plan.dump(1);
  const CliRun r =
      run("report --calibrate \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const CliRun cal = run("calibrate --json \"" + plan_path.string() + "\"");
  const CliRun ev = run("evaluate --json \"" + plan_path.string() + "\"");
  const json calibrated = json::parse(cal.out), evaluated = json::parse(ev.out);
  const std::string html = slurp(html_path);
  expectWellFormed(html, 5);  // layout, residuals, profile, map, correlation
  const std::set<std::string> shown = expectNumbersMatchEvaluate(html, evaluated, &calibrated);
  for (const char* p : {"/calibration/converged", "/calibration/chi2_per_dof", "/calibration/dof",
                        "/calibration/flagged", "/calibration/parameters/0/estimate",
                        "/calibration/parameters/2/u_posterior"}) {
    EXPECT_TRUE(shown.count(p)) << p;
  }
  // Every reading calibrate flags is marked on the residual plot and tabled; no other one.
  const int flagged = calibrated["flagged"].get<int>();
  ASSERT_GE(flagged, 1);
  int marked = 0;
  for (std::size_t j = 0; j < calibrated["residuals"].size(); ++j) {
    const auto& measurements = calibrated["residuals"][j]["measurements"];
    for (std::size_t m = 0; m < measurements.size(); ++m) {
      const std::string field = "/calibration/residuals/" + std::to_string(j) + "/measurements/" +
                                std::to_string(m) + "/score";
      const bool is_flagged = measurements[m]["flagged"].get<bool>();
      EXPECT_EQ(shown.count(field) == 1, is_flagged) << field;
      marked += is_flagged && html.find("<g data-field=\"" + field + "\"") != std::string::npos;
    }
  }
  EXPECT_EQ(marked, flagged);
  EXPECT_TRUE(calibrated["residuals"][3]["measurements"][1]["flagged"].get<bool>());
}

TEST_F(ReportCli, CalibrationOnlyWhenAskedOrSimulated) {
  const fs::path html_path = dir_ / "r.html";
  ASSERT_EQ(
      run("report \"" + data("ref-2r-calibrate.json") + "\" -o \"" + html_path.string() + "\"")
          .status,
      0);
  EXPECT_EQ(slurp(html_path).find("/calibration"), std::string::npos);
  // A plan written by `artcal simulate` carries a simulation block: its readings are calibrated.
  json plan = json::parse(std::ifstream(data("ref-2r-calibrate.json")));
  plan["simulation"] = {{"seed", 5}};
  const fs::path plan_path = dir_ / "simulated.json";
  std::ofstream(plan_path) << plan.dump(1);
  const CliRun r = run("report \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(html_path).find("data-field=\"/calibration/converged\""), std::string::npos);
}

// Readings simulated with a known truth: each estimate is shown against it, in its u.
TEST_F(ReportCli, SimulatedReadingsShowEstimateMinusTruthInU) {
  const auto [html, cal] = reportOfSimulated(data("ref-2r-calibrate.json"),
                                             R"({"l1": 150.02, "l2": 99.99, "dt2": 0.01})");
  ASSERT_FALSE(HasFailure());
  EXPECT_NE(html.find("<th>(estimate - truth) / u</th>"), std::string::npos);
  const double truths[] = {150.02, 99.99, 0.01};
  for (std::size_t k = 0; k < 3; ++k) {
    const json& p = cal["parameters"][k];
    const double z = (p["estimate"].get<double>() - truths[k]) / p["u"].get<double>();
    char cell[64];
    std::snprintf(cell, sizeof cell, "<td class=\"num\">%+.2f</td>", z);
    EXPECT_NE(html.find(cell), std::string::npos) << p["name"] << " " << cell;
  }
}

// A machine tool (docs/five-axis.md): the report names the location errors with u in um / urad
// and F, and after a calibration the controller table, each number the one calibrate --json gives
// (data-field pointers), and no NaN anywhere.
TEST_F(ReportCli, MachineToolShowsLocationErrorsAndTheControllerTable) {
  const auto [html, cal] =
      reportOfSimulated(test_support::planFile("machine-tool-trunnion-2spheres.json"),
                        R"({"E_X0C": -0.04, "E_Y0A": 0.03, "E_B0A": 0.002})");
  ASSERT_FALSE(HasFailure());
  EXPECT_EQ(html.find("nan"), std::string::npos);
  EXPECT_EQ(html.find("NaN"), std::string::npos);
  EXPECT_NE(html.find("<h3>Location errors (ISO 230-7)</h3>"), std::string::npos);
  EXPECT_NE(html.find("<h3>Controller table</h3>"), std::string::npos);
  // E_X0C's estimate (um) in the calibration's table, the C row's X offset in the controller's.
  const json& errors = cal.at("location_errors");
  ASSERT_EQ(errors.size(), 11u);
  for (std::size_t k = 0; k < errors.size(); ++k) {
    if (errors[k]["name"] != "E_X0C") continue;
    char cell[160];
    std::snprintf(cell, sizeof cell,
                  "data-field=\"/calibration/location_errors/%zu/estimate_fine\" "
                  "data-value=\"%s\">%+.2f</td>",
                  k, report_text::exact(errors[k]["estimate_fine"].get<double>()).c_str(),
                  errors[k]["estimate_fine"].get<double>());
    EXPECT_NE(html.find(cell), std::string::npos) << cell;
    EXPECT_NEAR(errors[k]["estimate_fine"].get<double>(), -40.0,
                3.0 * errors[k]["u_fine"].get<double>());
  }
  const json& entries = cal.at("controller_table").at("entries");
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string field =
        "data-field=\"/calibration/controller_table/entries/" + std::to_string(i) + "/value\"";
    EXPECT_NE(html.find(field), std::string::npos) << field;
  }
  // The procedure's columns are the machine's axes.
  EXPECT_NE(html.find("<th>A / deg</th><th>C / deg</th>"), std::string::npos);
}

// The controller table cannot be mistyped (docs/five-axis.md section 5): on the trunnion's
// sphere probing (calibrate "identifiable"), E_A0C, E_C0C and L, which the rank rule drops, are
// marked dropped with no value (null in JSON, "NOT MEASURED" in the table), each with the kept
// parameters it is tied to (E_A0A, none, E_Z0A); every determined entry carries calibrate's
// estimate and u (parameters) and U = 2 u; the chained form's C-from-A Y offset is E_Y0C - E_Y0A
// with u from the covariance --write-machine writes (var + var - 2 cov); calibrate's table names
// the dropped parameters and its JSON lists them.
TEST_F(ReportCli, ControllerTableMarksEachEntryDeterminedOrDroppedWithUAndU) {
  const auto [html, cal] =
      reportOfSimulated(test_support::planFile("machine-tool-trunnion-2spheres.json"),
                        R"({"E_X0C": -0.04, "E_Y0A": 0.03, "E_Y0C": 0.01, "E_B0A": 0.002})");
  ASSERT_FALSE(HasFailure());
  EXPECT_EQ(cal["calibrate_dropped"], json::array({"E_A0C", "E_C0C", "L"}));
  std::map<std::string, json> parameters, entries;
  for (const json& p : cal["parameters"]) parameters[p["name"]] = p;
  const json& table = cal["controller_table"];
  EXPECT_EQ(table["kind"], "actual location");
  EXPECT_DOUBLE_EQ(table["coverage_factor"].get<double>(), 2.0);
  for (const json& e : table["entries"]) entries[e["name"]] = e;
  ASSERT_EQ(entries.size(), 14u);
  const std::map<std::string, std::vector<std::string>> dropped = {
      {"E_A0C", {"E_A0A"}}, {"E_C0C", {}}, {"L", {"E_Z0A"}}};
  for (const auto& [name, e] : entries) {
    if (dropped.count(name)) {
      EXPECT_EQ(e["status"], "dropped") << name;
      EXPECT_TRUE(e["value"].is_null() && e["u"].is_null() && e["U"].is_null()) << name;
      EXPECT_EQ(e["tied_to"], json(dropped.at(name))) << name;
      continue;
    }
    ASSERT_TRUE(parameters.count(name)) << name;
    EXPECT_EQ(e["status"], "determined") << name;
    EXPECT_DOUBLE_EQ(e["value"].get<double>(), parameters[name]["estimate"].get<double>()) << name;
    EXPECT_DOUBLE_EQ(e["u"].get<double>(), parameters[name]["u"].get<double>()) << name;
    EXPECT_DOUBLE_EQ(e["U"].get<double>(), 2.0 * parameters[name]["u"].get<double>()) << name;
  }
  EXPECT_NE(entries["E_Z0A"]["note"].get<std::string>().find("dropped L"), std::string::npos);
  // The chained form against the machine file's covariance.
  const fs::path sim = dir_ / "sim.json", machine = dir_ / "cal.json";
  const CliRun text =
      run("calibrate \"" + sim.string() + "\" --write-machine \"" + machine.string() + "\"");
  ASSERT_EQ(text.status, 0);
  const json covariance = readJsonFile(machine.string())["covariance"];
  std::map<std::string, std::size_t> at;
  for (std::size_t i = 0; i < covariance["parameters"].size(); ++i)
    at[covariance["parameters"][i]] = i;
  const json& V = covariance["matrix"];
  const std::size_t ya = at.at("E_Y0A"), yc = at.at("E_Y0C");
  const double expected_u =
      std::sqrt(V[ya][ya].get<double>() + V[yc][yc].get<double>() - 2.0 * V[ya][yc].get<double>());
  const json& chained = table["chained_form"]["entries"];
  ASSERT_EQ(chained.size(), 3u);
  EXPECT_EQ(chained[1]["entry"], "Y offset from A");
  EXPECT_NEAR(
      chained[1]["value"].get<double>(),
      parameters["E_Y0C"]["estimate"].get<double>() - parameters["E_Y0A"]["estimate"].get<double>(),
      1e-15);
  EXPECT_NEAR(chained[1]["u"].get<double>(), expected_u, 1e-9 * expected_u);
  // The table: the dropped rows say NOT MEASURED and hold no number before their note.
  for (const char* row : {"  C     tilt about X         dropped      NOT MEASURED\n",
                          "  C     zero                 dropped      NOT MEASURED\n",
                          "  tool  tool length          dropped      NOT MEASURED\n"})
    EXPECT_NE(text.out.find(row), std::string::npos) << row << text.out;
  EXPECT_NE(text.out.find("not calibrated, dropped by the rank rule"), std::string::npos);
  EXPECT_NE(text.out.find("  L: +1 L  -"), std::string::npos) << text.out;
  EXPECT_NE(
      html.find(
          "data-field=\"/calibration/controller_table/entries/13/value\" data-value=\"null\""),
      std::string::npos);
}

/// A planar 2R plan with `count` ball-bar placements spread over the reach annulus, readings by
/// inverse kinematics (fixed seed).
// An instrument plan's held-out stations (report --held-out): the table and histogram read the
// deviations `verify` gives of the same readings with the nominal machine and with the machine
// `calibrate --write-machine` writes; each station's residual figure draws calibrate's residuals.
TEST_F(ReportCli, HeldOutStationsEqualVerifyWithTheNominalAndTheCalibratedMachine) {
  const std::string plan = data("ref-instrument-arm6-2stations.json");
  const std::string truth = test_support::planFile("tracker-arm6/truth.json");
  const fs::path trained = dir_ / "trained.json", held = dir_ / "held.json",
                 cal = dir_ / "cal.json", html_path = dir_ / "r.html";
  ASSERT_EQ(run("simulate \"" + plan + "\" --truth \"" + truth + "\" --seed 3 -o \"" +
                trained.string() + "\"")
                .status,
            0);
  // Other readings of the same machine: the same configurations, drawn again; the first 8 of each
  // station fit the station, the other 17 are held out.
  const fs::path drawn = dir_ / "drawn.json";
  ASSERT_EQ(run("simulate \"" + plan + "\" --truth \"" + truth + "\" --seed 11 -o \"" +
                drawn.string() + "\"")
                .status,
            0);
  json held_plan = json::parse(std::ifstream(drawn));
  for (json& placement : held_plan["placements"])
    for (std::size_t m = 0; m < 8; ++m) placement["measurements"][m]["stationing"] = true;
  std::ofstream(held) << held_plan.dump(1);

  const CliRun r = run("report \"" + trained.string() + "\" --held-out \"" + held.string() +
                       "\" --json -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const json summary = json::parse(r.out);
  const auto [nominal, calibrated] = verifiedNominalAndCalibrated(trained, held, cal);
  const json& shown = summary.at("held_out");
  for (const auto& [machine, verified] :
       {std::pair{"nominal", &nominal}, std::pair{"calibrated", &calibrated}}) {
    SCOPED_TRACE(machine);
    const json& expected = verified->at("instrument");
    ASSERT_EQ(shown[machine]["stations"].size(), 2u);
    for (std::size_t s = 0; s < 2; ++s) {
      const json& mine = shown[machine]["stations"][s]["deviations"];
      const json& theirs = expected["stations"][s]["deviations"];
      ASSERT_EQ(mine.size(), 17u);
      ASSERT_EQ(theirs.size(), 17u);
      for (std::size_t i = 0; i < mine.size(); ++i)
        EXPECT_NEAR(mine[i].get<double>(), theirs[i].get<double>(),
                    1e-9 * (1.0 + theirs[i].get<double>()));
    }
    EXPECT_NEAR(shown[machine]["all"]["rms"].get<double>(), expected["all"]["rms"].get<double>(),
                1e-9);
  }
  // The truth is off nominal by 0.1-0.25 mm: calibrated, the held-out readings fit to the noise.
  EXPECT_LT(shown["calibrated"]["all"]["rms"].get<double>(),
            0.3 * shown["nominal"]["all"]["rms"].get<double>());

  const std::string html = slurp(html_path);
  EXPECT_EQ(xmlFault(html), std::nullopt);
  int held_fields = 0;
  for (const Shown& s : shownNumbers(html)) {
    if (s.pointer.rfind("/held_out/", 0) != 0) continue;
    ++held_fields;
    EXPECT_EQ(std::stod(s.value), shown.at(json::json_pointer(s.pointer.substr(9))).get<double>())
        << s.pointer;
  }
  EXPECT_EQ(held_fields, 9);  // readings, mean, RMS, max of each; the calibrated predicted RMS
  std::set<std::string> figures;
  for (const json& f : summary["figures"]) figures.insert(f["name"].get<std::string>());
  for (const char* name : {"station-0", "station-1", "held-out-deviations"})
    EXPECT_TRUE(figures.count(name)) << name;
  // One residual vector per reading of each station, named by calibrate's pointer.
  for (int j = 0; j < 2; ++j)
    for (int m = 0; m < 25; ++m) {
      const std::string field = "data-field=\"/calibration/residuals/" + std::to_string(j) +
                                "/measurements/" + std::to_string(m) + "/residual\"";
      EXPECT_NE(html.find(field), std::string::npos) << field;
    }

  // The held-out readings of another machine: refused with its pointer, no report written.
  fs::remove(html_path);
  const CliRun other = run("report \"" + trained.string() + "\" --held-out \"" +
                           data("ref-2r-calibrate.json") + "\" -o \"" + html_path.string() + "\"");
  EXPECT_EQ(other.status, 2);
  EXPECT_EQ(other.err.rfind("error: " + data("ref-2r-calibrate.json") + ": /machine: ", 0), 0u)
      << other.err;
  EXPECT_EQ(std::count(other.err.begin(), other.err.end(), '\n'), 1);
  EXPECT_FALSE(fs::exists(html_path));
}

TEST_F(ReportCli, HeldOutPoseAnglesEqualVerifyWithTheNominalAndTheCalibratedMachine) {
  // A 6-DOF tracker (plans/tracker-arm6-pose.json: 2 stations x 25 poses, the first 8 of each
  // marked stationing): the held-out poses' angular deviations in the report are verify's.
  const std::string plan = test_support::planFile("tracker-arm6-pose.json");
  const std::string truth = test_support::planFile("tracker-arm6/truth.json");
  const fs::path trained = dir_ / "trained.json", held = dir_ / "held.json",
                 cal = dir_ / "cal.json", html_path = dir_ / "r.html";
  for (const auto& [seed, file] : {std::pair{3, trained}, std::pair{11, held}}) {
    ASSERT_EQ(run("simulate \"" + plan + "\" --truth \"" + truth + "\" --seed " +
                  std::to_string(seed) + " -o \"" + file.string() + "\"")
                  .status,
              0);
  }
  const CliRun r = run("report \"" + trained.string() + "\" --held-out \"" + held.string() +
                       "\" --json -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const json shown = json::parse(r.out).at("held_out");
  const auto [nominal, calibrated] = verifiedNominalAndCalibrated(trained, held, cal);
  const auto close = [](const json& a, const json& b) {
    return std::abs(a.get<double>() - b.get<double>()) <= 1e-9 * (1.0 + std::abs(b.get<double>()));
  };
  const std::map<std::string, const json*> verified = {{"nominal", &nominal},
                                                       {"calibrated", &calibrated}};
  for (const auto& [machine, verify] : verified) {
    SCOPED_TRACE(machine);
    const json& expected = verify->at("instrument");
    ASSERT_EQ(shown[machine]["stations"].size(), 2u);
    for (std::size_t s = 0; s < 2; ++s) {
      const json& mine = shown[machine]["stations"][s]["angular"]["deviations"];
      const json& theirs = expected["stations"][s]["angular"]["deviations"];
      ASSERT_EQ(mine.size(), 17u);
      ASSERT_EQ(theirs.size(), 17u);
      for (std::size_t i = 0; i < mine.size(); ++i) EXPECT_TRUE(close(mine[i], theirs[i])) << i;
    }
    EXPECT_TRUE(close(shown[machine]["angular_all"]["rms"], expected["angular_all"]["rms"]));
  }
  // The truth's angles are off nominal by 0.015-0.03 deg: the calibrated machine's held-out
  // orientations fit far better than the nominal's, near their predicted RMS.
  const json& angles = shown["calibrated"]["angular_all"];
  EXPECT_LT(angles["rms"].get<double>(),
            0.5 * shown["nominal"]["angular_all"]["rms"].get<double>());
  EXPECT_LT(angles["rms"].get<double>(), 1.5 * angles["predicted_rms"].get<double>());
  EXPECT_GT(angles["rms"].get<double>(), 0.67 * angles["predicted_rms"].get<double>());

  // Every angular number of the HTML is verify's value at the same pointer.
  const std::string html = slurp(html_path);
  EXPECT_EQ(xmlFault(html), std::nullopt);
  int angular_fields = 0;
  for (const Shown& s : shownNumbers(html)) {
    if (s.pointer.rfind("/held_out/", 0) != 0 || s.pointer.find("angular") == std::string::npos)
      continue;
    ++angular_fields;
    const std::string rest = s.pointer.substr(std::string("/held_out/").size());
    const std::string machine = rest.substr(0, rest.find('/'));
    const json& verify = *verified.at(machine);
    const json::json_pointer at("/instrument" + rest.substr(machine.size()));
    ASSERT_TRUE(verify.contains(at)) << s.pointer;
    EXPECT_TRUE(close(json(std::stod(s.value)), verify.at(at))) << s.pointer;
  }
  // 2 stations and all, with each machine: readings, mean, RMS, max; the calibrated predicted RMS.
  EXPECT_EQ(angular_fields, 3 * 4 + 3 * 5);
}

json largePlan(int count) {
  json plan = json::parse(std::ifstream(test_support::testDataFile("ref-2r-5bars.json")));
  Eigen::VectorXd p(3);
  p << 150.0, 100.0, 0.0;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> radius(70.0, 230.0), angle(-M_PI, M_PI);
  json placements = json::array();
  while (static_cast<int>(placements.size()) < count) {
    const double r = radius(rng), a = angle(rng), turn = angle(rng);
    const Eigen::Vector2d first(r * std::cos(a), r * std::sin(a));
    const Eigen::Vector2d second = first + 80.0 * Eigen::Vector2d(std::cos(turn), std::sin(turn));
    const auto q0 = planar2rInverse(p, first), q1 = planar2rInverse(p, second);
    if (q0.empty() || q1.empty()) continue;
    const auto reading = [](int feature, const Eigen::VectorXd& q) {
      return json{{"feature", feature}, {"joints", {radToDeg(q[0]), radToDeg(q[1])}}};
    };
    placements.push_back(
        {{"artifact", "bar80"}, {"measurements", {reading(0, q0[0]), reading(1, q1[0])}}});
  }
  plan["placements"] = placements;
  plan["workspace"] = {{"samples", 4096}, {"seed", 3}};
  return plan;
}

TEST_F(ReportCli, ThousandPlacementReportStaysUnderTwoMegabytes) {
  const fs::path plan_path = dir_ / "large.json", html_path = dir_ / "r.html";
  std::ofstream(plan_path) << largePlan(1000).dump();
  const CliRun r = run("report \"" + plan_path.string() + "\" -o \"" + html_path.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::uintmax_t bytes = fs::file_size(html_path);
  EXPECT_LT(bytes, 2u * 1024u * 1024u) << bytes;
  const std::string html = slurp(html_path);
  expectWellFormed(html, 4);
  // Every placement is drawn: 2000 features, none sampled away.
  std::size_t features = 0;
  for (std::size_t at = 0; (at = html.find("<title>placement ", at)) != std::string::npos; ++at) {
    ++features;
  }
  EXPECT_EQ(features, 2000u);
}

// The profile of `evaluate --json` against figures computed apart from it: each row's
// configurations from the law of cosines here (t1 = 0, both elbow branches), S_m and S_q at them
// from tipUncertainty, and the encoders' share against its closed form s_q sqrt(rho^2 + l2^2)
// (method.md section 8). Swapping the kinematic and encoder columns fails.
TEST(ProfileJson, ColumnsAreTheTipFiguresAtTheSameConfigurations) {
  const Plan plan = loadPlan(test_support::planFile("paper-2r-5bars.json"));
  const Evaluation ev = evaluatePlan(plan);
  ASSERT_TRUE(ev.covariance);
  const json profile = evaluationToJson(plan, ev).at("profile");
  ASSERT_EQ(profile.size(), 20u);  // 21 steps of 50..250 mm; t2's limit (170 deg) drops 50 mm
  const double l1 = plan.machine.nominal[0], l2 = plan.machine.nominal[1];
  const double dt2 = plan.machine.nominal[2];
  const double s_q = plan.noise.encoder[0];
  ASSERT_EQ(plan.noise.encoder[1], s_q);
  for (const json& row : profile) {
    const double rho = row.at("reach").get<double>();
    SCOPED_TRACE(rho);
    std::optional<TipPoint> worst;
    for (double sign : {1.0, -1.0}) {
      const double c = std::clamp((rho * rho - l1 * l1 - l2 * l2) / (2 * l1 * l2), -1.0, 1.0);
      const double t2 = sign * std::acos(c) - dt2;
      if (t2 < plan.machine.joint_limits[1][0] || t2 > plan.machine.joint_limits[1][1]) continue;
      const TipPoint tip =
          tipUncertainty(plan.machine, plan.noise, Eigen::Vector2d(0.0, t2), ev.covariance->V);
      if (!worst || tip.total > worst->total) worst = tip;
    }
    ASSERT_TRUE(worst);
    EXPECT_NEAR(row.at("kinematic").get<double>(), worst->kinematic, 1e-12);
    EXPECT_NEAR(row.at("encoder").get<double>(), s_q * std::hypot(rho, l2), 1e-12);
    EXPECT_NEAR(row.at("total").get<double>(), std::hypot(worst->kinematic, worst->encoder), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------
// A Cartesian CMM's error functions drawn along their axes (cartesian_report.hpp).

/// The numbers of the curve of `function` (data-curve `curve`) in a figure: positions, values.
std::pair<std::vector<double>, std::vector<double>> curveNumbers(const std::string& svg,
                                                                 const std::string& function,
                                                                 const std::string& curve) {
  const std::regex pattern(
      "data-function=\"" + std::regex_replace(function, std::regex("\\."), "\\.") +
      "\" data-curve=\"" + curve + "\" data-position=\"([^\"]*)\" data-value=\"([^\"]*)\"");
  std::smatch m;
  if (!std::regex_search(svg, m, pattern)) return {};
  const auto numbers = [](const std::string& text) {
    std::vector<double> out;
    std::istringstream in(text);
    for (double v; in >> v;) out.push_back(v);
    return out;
  };
  return {numbers(m[1]), numbers(m[2])};
}

/// P_1..P_3 written out (not Bonnet's recursion, which the model uses).
double legendreExplicit(int n, double s) {
  switch (n) {
    case 1:
      return s;
    case 2:
      return 0.5 * (3.0 * s * s - 1.0);
    default:
      return 0.5 * (5.0 * s * s * s - 3.0 * s);
  }
}

struct CmmCurvesCase {
  Plan plan = loadPlan(test_support::planFile("cmm-plate-3planes.json"));
  const AxisErrorFunctions& cmm = *axisErrorFunctionsOf(plan);
  Eigen::MatrixXd V;
  Eigen::VectorXd estimate, truth;

  CmmCurvesCase() {
    const int n = plan.machine.calibratedCount();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    Eigen::MatrixXd B(n, n);
    for (int i = 0; i < n * n; ++i) B.data()[i] = unit(rng);
    V = 1e-12 * (B * B.transpose() + Eigen::MatrixXd::Identity(n, n));  // (um)^2 scale
    estimate = truth = plan.machine.nominal;
    for (const int i : plan.machine.calibrated) {
      estimate[i] = 2e-3 * unit(rng);
      truth[i] = estimate[i] + 1e-6 * unit(rng);
    }
  }
  // e(u) and u_e(u) of `function` of axis `k` at reading `u`, independently of the code.
  std::pair<double, double> expected(int k, AxisError error, double u,
                                     const Eigen::VectorXd& p) const {
    const auto& range = cmm.axes()[static_cast<std::size_t>(k)].range;
    const double s = (2.0 * u - range[0] - range[1]) / (range[1] - range[0]);
    const auto& calibrated = plan.machine.calibrated;
    Eigen::VectorXd g = Eigen::VectorXd::Zero(plan.machine.calibratedCount());
    double value = 0.0;
    for (int n = 1; n <= 3; ++n) {
      const int i = cmm.parameterIndex(k, error, n);
      value += legendreExplicit(n, s) * p[i];
      const auto at = std::find(calibrated.begin(), calibrated.end(), i);
      if (at != calibrated.end()) g[at - calibrated.begin()] = legendreExplicit(n, s);
    }
    return {value, std::sqrt(g.dot(V * g))};
  }
};

TEST(ErrorFunctionFigures, CurvesAreTheLegendreSeriesAndTheirBands) {
  const CmmCurvesCase c;
  ASSERT_EQ(c.cmm.degree(), 3);
  const auto figures =
      errorFunctionFigures(c.plan, errorFunctionBands(c.plan, c.V, c.estimate, true, &c.truth, 11));
  ASSERT_EQ(figures.size(), 9u);  // per axis: translations, rotations, recovery
  std::map<std::string, std::string> by_name;
  for (const ReportFigure& f : figures) {
    EXPECT_EQ(xmlFault(f.svg), std::nullopt) << f.name;
    by_name[f.name] = f.svg;
  }
  int checked = 0;
  for (int k = 0; k < 3; ++k) {
    const std::string axis = c.cmm.axes()[static_cast<std::size_t>(k)].name;
    for (int e = 0; e < kAxisErrorCount; ++e) {
      const auto error = static_cast<AxisError>(e);
      const bool rotation = e >= 3;
      const double scale = rotation ? 1e6 : 1e3;  // um/m, um
      const std::string name = axis + "." + axisErrorName(error);
      const std::string& band =
          by_name.at("error-functions-" + axis + (rotation ? "-rotations" : "-translations"));
      const auto [position, centre] = curveNumbers(band, name, "centre");
      const auto [position_up, upper] = curveNumbers(band, name, "upper");
      const auto [position_low, lower] = curveNumbers(band, name, "lower");
      const auto [position_rec, recovery] =
          curveNumbers(by_name.at("error-functions-" + axis + "-recovery"), name, "recovery");
      ASSERT_EQ(position.size(), 11u) << name;
      ASSERT_EQ(upper.size(), 11u) << name;
      ASSERT_EQ(lower.size(), 11u) << name;
      for (std::size_t i = 0; i < position.size(); ++i) {
        const auto [value, u] = c.expected(k, error, position[i], c.estimate);
        const double true_value = c.expected(k, error, position[i], c.truth).first;
        EXPECT_NEAR(centre[i], scale * value, 1e-9 * scale * (std::abs(value) + u)) << name;
        EXPECT_NEAR(upper[i] - centre[i], scale * u, 1e-9 * scale * u) << name;
        EXPECT_NEAR(centre[i] - lower[i], scale * u, 1e-9 * scale * u) << name;
        const auto at = std::find(position_rec.begin(), position_rec.end(), position[i]);
        if (at == position_rec.end()) continue;  // u = 0 there: no ratio
        EXPECT_NEAR(recovery[static_cast<std::size_t>(at - position_rec.begin())],
                    (value - true_value) / u, 1e-7)
            << name;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
  // At nominal (evaluate): the band alone, symmetric about 0, no estimate and no recovery.
  const auto predicted =
      errorFunctionFigures(c.plan, errorFunctionBands(c.plan, c.V, c.plan.machine.nominal, false));
  ASSERT_EQ(predicted.size(), 6u);
  const auto [position, upper] = curveNumbers(predicted[0].svg, "y.tx", "upper");
  const auto [position_low, lower] = curveNumbers(predicted[0].svg, "y.tx", "lower");
  ASSERT_EQ(upper.size(), 21u);
  EXPECT_EQ(curveNumbers(predicted[0].svg, "y.tx", "centre").first.size(), 0u);
  for (std::size_t i = 0; i < upper.size(); ++i) {
    EXPECT_NEAR(upper[i], 1e3 * c.expected(0, AxisError::Tx, position[i], c.estimate).second,
                1e-9 * upper[i]);
    EXPECT_EQ(lower[i], -upper[i]);
  }
}

TEST_F(ReportCli, CartesianReportDrawsTheErrorFunctions) {
  const fs::path html_path = dir_ / "r.html", svg_dir = dir_ / "svg";
  const CliRun r = run("report \"" + data("ref-cartesian-plate.json") + "\" -o \"" +
                       html_path.string() + "\" --svg \"" + svg_dir.string() + "\" --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const json summary = json::parse(r.out);
  std::set<std::string> names;
  for (const json& f : summary.at("figures")) names.insert(f.at("name").get<std::string>());
  const Plan plan = loadPlan(data("ref-cartesian-plate.json"));
  for (const CartesianAxis& axis : axisErrorFunctionsOf(plan)->axes()) {
    for (const char* kind : {"-translations", "-rotations"}) {
      const std::string name = "error-functions-" + axis.name + kind;
      ASSERT_TRUE(names.count(name)) << name;
      const std::string svg = slurp(svg_dir / (name + ".svg"));
      EXPECT_EQ(xmlFault(svg), std::nullopt) << name;
      EXPECT_NE(svg.find("data-curve=\"upper\""), std::string::npos) << name;
    }
  }
}

// The controller table and the location-error table of a machine tool read their numbers in the
// units their headings name (docs/five-axis.md): a parameter vector with a distinct value in each
// location error (offsets in mm, orientations in rad internally), the oracle here from the ISO
// 230-7 names alone: E_<error>0<axis> is the row of <axis>, column <error>; A, B, C in deg
// (180 / pi per rad) and urad, X, Y, Z in mm and um.
TEST(LocationErrors, ControllerAndLocationTablesShowEachValueInItsHeadingsUnit) {
  const Plan base = loadPlan(test_support::planFile("machine-tool-trunnion-2spheres.json"));
  const auto& infos = base.machine.mechanism->parameters();
  Plan plan = base;
  plan.machine.calibrated.clear();
  Eigen::VectorXd p = base.machine.nominal;
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const std::string& name = infos[i].name;
    if (name.size() != 5 || name.rfind("E_", 0) != 0) continue;
    const bool angle = name[2] >= 'A' && name[2] <= 'C';
    const auto k = static_cast<double>(i + 1);
    p[static_cast<Eigen::Index>(i)] = angle ? -1e-4 * k : 0.01 * k;  // rad or mm
    plan.machine.calibrated.push_back(static_cast<int>(i));
  }
  ASSERT_GE(plan.machine.calibrated.size(), 8u);
  constexpr double kDegPerRad = 180.0 / std::numbers::pi;
  const json table = controllerTableToJson(plan, p, nullptr);
  std::map<char, std::map<char, double>> cells;  // axis -> column -> expected value
  for (const int i : plan.machine.calibrated) {
    const std::string& name = infos[static_cast<std::size_t>(i)].name;
    const bool angle = name[2] >= 'A' && name[2] <= 'C';
    cells[name[4]][name[2]] = angle ? p[i] * kDegPerRad : p[i];
  }
  ASSERT_EQ(table["axes"].size(), cells.size());
  for (const json& row : table["axes"]) {
    const char axis = row["axis"].get<std::string>()[0];
    ASSERT_TRUE(cells.count(axis)) << axis;
    std::map<char, double>& expected = cells[axis];
    for (const char c : {'X', 'Y', 'Z'})
      EXPECT_NEAR(row["offset_mm"][std::string(1, c)].get<double>(), expected[c], 1e-12)
          << axis << c;
    for (const char c : {'A', 'B', 'C'})
      EXPECT_NEAR(row["orientation_deg"][std::string(1, c)].get<double>(), expected[c], 1e-12)
          << axis << c;
  }
  // The location errors: u and the estimate in deg and urad or mm and um.
  ParameterCovariance covariance;
  const auto n = static_cast<Eigen::Index>(plan.machine.calibrated.size());
  covariance.u = Eigen::VectorXd::LinSpaced(n, 1e-6, 2e-5);
  covariance.confounding = Eigen::VectorXd::LinSpaced(n, 1.0, 3.0);
  const json errors = locationErrorsToJson(plan, covariance, &p);
  ASSERT_EQ(errors.size(), static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) {
    const json& row = errors[static_cast<std::size_t>(k)];
    const int i = plan.machine.calibrated[static_cast<std::size_t>(k)];
    const bool angle = infos[static_cast<std::size_t>(i)].name[2] <= 'C';
    const double u = covariance.u[k];
    EXPECT_EQ(row["unit"], angle ? "deg" : "mm");
    EXPECT_EQ(row["unit_fine"], angle ? "urad" : "um");
    EXPECT_NEAR(row["u"].get<double>(), angle ? u * kDegPerRad : u, 1e-15);
    EXPECT_NEAR(row["u_fine"].get<double>(), angle ? u * 1e6 : u * 1e3, 1e-12);
    EXPECT_NEAR(row["estimate"].get<double>(), angle ? p[i] * kDegPerRad : p[i], 1e-12);
    EXPECT_NEAR(row["estimate_fine"].get<double>(), angle ? p[i] * 1e6 : p[i] * 1e3, 1e-9);
    EXPECT_DOUBLE_EQ(row["confounding_index"].get<double>(), covariance.confounding[k]);
  }
}

// An entry the plan's calibrate list leaves out is held, with no value and the reason; with the
// rank rule's resolution, a weakly determined one is held with its surviving fraction, a dropped
// one is dropped with the kept ones its tie names. Built here by hand (no fit): L left out, E_C0C
// weak (fraction 3e-9), E_A0C dropped tied to E_A0A, the rest determined with u = 1e-3 mm or rad.
TEST(LocationErrors, HeldAndDroppedEntriesHaveNoValueAndSayWhy) {
  Plan plan = loadPlan(test_support::planFile("machine-tool-trunnion-2spheres.json"));
  const Mechanism& m = *plan.machine.mechanism;
  const int l = m.parameterIndex("L"), c0c = m.parameterIndex("E_C0C"),
            a0c = m.parameterIndex("E_A0C"), a0a = m.parameterIndex("E_A0A");
  plan.machine.calibrated.clear();
  for (int i = 0; i < m.parameterCount(); ++i)
    if (i != l && i != c0c && i != a0c) plan.machine.calibrated.push_back(i);
  CalibratedSetResolution resolution;
  resolution.dropped = {a0c};
  resolution.ties = {{{a0c, 1.0}, {a0a, -0.7}}};
  resolution.weak = {c0c};
  resolution.weak_fraction = {3e-9};
  plan.calibrate_resolution = resolution;
  ParameterCovariance covariance;
  const auto n = static_cast<Eigen::Index>(plan.machine.calibrated.size());
  covariance.V = Eigen::MatrixXd::Identity(n, n) * 1e-6;
  covariance.u = Eigen::VectorXd::Constant(n, 1e-3);
  Eigen::VectorXd p = plan.machine.nominal;
  p[l] = 123.0;
  const json table = controllerTableToJson(plan, p, &covariance);
  std::map<std::string, json> entries;
  for (const json& e : table["entries"]) entries[e["name"]] = e;
  EXPECT_EQ(entries["L"]["status"], "held");
  EXPECT_TRUE(entries["L"]["value"].is_null());
  EXPECT_DOUBLE_EQ(entries["L"]["kept_value"].get<double>(), 123.0);
  EXPECT_NE(entries["L"]["note"].get<std::string>().find("calibrate list"), std::string::npos);
  EXPECT_EQ(entries["E_C0C"]["status"], "held");
  EXPECT_NE(entries["E_C0C"]["note"].get<std::string>().find("3e-09"), std::string::npos)
      << entries["E_C0C"]["note"];
  EXPECT_EQ(entries["E_A0C"]["status"], "dropped");
  EXPECT_EQ(entries["E_A0C"]["tied_to"], json::array({"E_A0A"}));
  EXPECT_EQ(entries["E_Y0A"]["status"], "determined");
  EXPECT_DOUBLE_EQ(entries["E_Y0A"]["U"].get<double>(), 2e-3);                             // mm
  EXPECT_NEAR(entries["E_B0A"]["u"].get<double>(), 1e-3 * 180 / std::numbers::pi, 1e-15);  // deg
  const std::string text = controllerTable(plan, p, &covariance);
  EXPECT_NE(text.find("  tool  tool length          held         NOT MEASURED\n        L held at "
                      "123.0000 mm in the fit; fixed by the plan's calibrate list"),
            std::string::npos)
      << text;
}

}  // namespace report_test
}  // namespace artcal
