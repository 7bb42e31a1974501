// The HTML report in a real browser (issue 14 point 5): `artcal report` of example plans printed
// to PDF by headless Chromium (Debian's chromium), read back with pdfinfo and pdftotext
// (poppler-utils): the page count (the procedure starts each placement on a new A4 page), the
// section titles, and numbers of `evaluate --json` and `procedure --json` as the report prints
// them. Skipped, saying so, when chromium or poppler-utils is missing. Slow (several seconds
// per plan in Chromium): labelled with the report layer, meant for the full check.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace artcal {
namespace report_pdf_test {

namespace fs = std::filesystem;
using nlohmann::json;
using test_support::runCli;

bool haveProgram(const std::string& name) {
  return std::system(("command -v " + name + " >/dev/null 2>&1").c_str()) == 0;
}

/// stdout of a shell command (stderr discarded).
std::string shellOutput(const std::string& command) {
  std::string out;
  FILE* pipe = popen((command + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return out;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) out.append(buffer, n);
  pclose(pipe);
  return out;
}

std::string format(const char* fmt, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, value);
  return buffer;
}

struct Pdf {
  int pages = 0;
  std::string text;
};

/// The report of `plan` printed to PDF by Chromium, read back by poppler.
Pdf renderReport(const std::string& plan, const fs::path& folder) {
  fs::create_directories(folder);
  const fs::path html = folder / "report.html", pdf = folder / "report.pdf";
  EXPECT_EQ(runCli("report " + plan + " -o " + html.string()).status, 0);
  std::system(("chromium --headless --no-sandbox --disable-gpu --disable-dev-shm-usage "
               "--no-first-run --no-pdf-header-footer --print-to-pdf=" +
               pdf.string() + " file://" + html.string() + " >/dev/null 2>&1")
                  .c_str());
  Pdf out;
  const std::string info = shellOutput("pdfinfo " + pdf.string());
  const auto at = info.find("Pages:");
  if (at != std::string::npos) out.pages = std::atoi(info.c_str() + at + 6);
  out.text = shellOutput("pdftotext -layout " + pdf.string() + " -");
  return out;
}

void expectPrintedReport(const std::string& name) {
  if (!haveProgram("chromium")) {
    GTEST_SKIP() << "chromium is not installed (Debian package chromium): the report is not "
                    "rendered to PDF here";
  }
  if (!haveProgram("pdftotext") || !haveProgram("pdfinfo")) {
    GTEST_SKIP() << "pdftotext/pdfinfo are not installed (Debian package poppler-utils)";
  }
  const std::string plan = test_support::planFile(name + ".json");
  const fs::path folder =
      fs::temp_directory_path() / ("artcal-pdf-" + std::to_string(getpid()) + "-" + name);
  const Pdf pdf = renderReport(plan, folder);
  fs::remove_all(folder);
  const json evaluation = json::parse(runCli("evaluate --json " + plan).out);
  const json procedure = json::parse(runCli("procedure --json " + plan).out);
  const std::size_t placements = procedure.at("placements").size();
  // The report's pages, then one page at least per placement of the procedure.
  EXPECT_GE(pdf.pages, static_cast<int>(placements) + 1);
  EXPECT_LE(pdf.pages, static_cast<int>(placements) * 3 + 12);
  for (const char* title :
       {"Identifiability", "Layout", "Parameters", "Tip uncertainty", "Procedure", "Placement 0"}) {
    EXPECT_NE(pdf.text.find(title), std::string::npos) << title;
  }
  EXPECT_NE(pdf.text.find("Placement " + std::to_string(placements - 1)), std::string::npos);
  // Numbers as the report prints them: u of the first length parameter and the worst tip in um
  // (3 decimals), the first target joint value of the procedure (4 decimals).
  for (const json& p : evaluation.at("parameters")) {
    if (p.at("unit") != "mm") continue;
    const std::string u = format("%.3f", p.at("u").get<double>() * 1e3);
    EXPECT_NE(pdf.text.find(u), std::string::npos) << p.at("name") << " u " << u;
    break;
  }
  const std::string worst =
      format("%.3f", evaluation.at("/tip/worst/total"_json_pointer).get<double>() * 1e3);
  EXPECT_NE(pdf.text.find(worst), std::string::npos) << "worst tip " << worst;
  const std::string q1 =
      format("%.4f", procedure.at("/placements/0/readings/0/joints/0"_json_pointer).get<double>());
  EXPECT_NE(pdf.text.find(q1), std::string::npos) << "first target joint " << q1;
}

TEST(ReportPdf, PlanarArmPrints) {
  expectPrintedReport("paper-2r-5bars");
}
TEST(ReportPdf, SixAxisArmPrints) {
  expectPrintedReport("aacmm-6axis-3bars");
}
TEST(ReportPdf, HexapodPrints) {
  expectPrintedReport("hexapod-10bars-optimized");
}
TEST(ReportPdf, CartesianCmmPrints) {
  expectPrintedReport("cmm-plate-xy");
}

}  // namespace report_pdf_test
}  // namespace artcal
