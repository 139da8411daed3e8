// The report of throng verify: report.md (a table of every test, then each
// test's criteria beside the measured values and its chart), report.json
// (the same, with the measured figures) and one PNG chart per test run.
#include <cstdio>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "app/verification.h"
#include "app/version.h"
#include "core/error.h"
#include "io/run_outputs.h"

namespace throng::app {

namespace {

std::string model_text(const VerifyOptions& o) {
  return o.model ? std::string(sim::to_string(*o.model)) : std::string("as the files say (the default model)");
}

std::string png_name(int number) { return fmt::format("rimea_{:02d}.png", number); }

// Table cells must not break the Markdown table.
std::string cell(std::string s) {
  for (char& ch : s)
    if (ch == '|' || ch == '\n') ch = ' ';
  return s;
}

std::string markdown_summary(const std::vector<VerifyResult>& results, const VerifyOptions& o) {
  int pass = 0, fail = 0, na = 0;
  for (const VerifyResult& r : results)
    (r.status == VerifyStatus::pass ? pass : r.status == VerifyStatus::fail ? fail : na) += 1;
  std::string md = "# RiMEA 3.0 verification of throng\n\n";
  md += fmt::format("throng {}, steering model: {}. Criteria in our words and their sources: docs/verification.md.\n\n",
                    kVersion, model_text(o));
  md += fmt::format("**{} passed, {} failed, {} not applicable.**\n\n", pass, fail, na);
  md += "| test | title | result |\n| --- | --- | --- |\n";
  for (const VerifyResult& r : results)
    md += fmt::format("| {} | {} | {} |\n", r.number, cell(r.title),
                      r.status == VerifyStatus::fail ? "**fail**" : to_string(r.status));
  return md;
}

std::string markdown_test(const VerifyResult& r, bool has_png) {
  std::string md = fmt::format("\n## Test {}: {}\n\n", r.number, r.title);
  if (r.status == VerifyStatus::not_applicable) return md + "Not applicable: " + r.reason + ".\n";
  md += fmt::format("Result: **{}** ({:.1f} s of wall time). Scenarios:", to_string(r.status), r.wall_s);
  for (const std::string& s : r.scenarios) md += " `examples/verification/" + s + ".yaml`";
  md += "\n\n| criterion | measured | |\n| --- | --- | --- |\n";
  for (const VerifyCheck& c : r.checks)
    md += fmt::format("| {} | {} | {} |\n", cell(c.criterion), cell(c.measured), c.pass ? "pass" : "**fail**");
  if (has_png) md += fmt::format("\n![Test {}]({})\n", r.number, png_name(r.number));
  return md;
}

nlohmann::json result_json(const VerifyResult& r, bool has_png) {
  nlohmann::json j = {{"number", r.number}, {"title", r.title}, {"status", to_string(r.status)}};
  if (r.status == VerifyStatus::not_applicable) {
    j["reason"] = r.reason;
    return j;
  }
  j["scenarios"] = r.scenarios;
  j["checks"] = nlohmann::json::array();
  for (const VerifyCheck& c : r.checks)
    j["checks"].push_back({{"criterion", c.criterion}, {"measured", c.measured}, {"pass", c.pass}});
  j["figures"] = r.figures;
  j["wall_s"] = r.wall_s;
  if (has_png) j["plot"] = png_name(r.number);
  return j;
}

// Writes the chart's PNG when this build has the renderer; false when not.
bool write_chart(const std::string& dir, const VerifyResult& r) {
  if (!r.chart) return false;
#if defined(THRONG_HAVE_RENDER)
  render::write_chart_png(dir + "/" + png_name(r.number), *r.chart);
  return true;
#else
  (void)dir;
  return false;
#endif
}

}  // namespace

std::vector<std::string> write_verification_report(const std::string& dir, const std::vector<VerifyResult>& results,
                                                   const VerifyOptions& o) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("cannot create the output folder: " + ec.message(), at_field("--out", dir));
  std::vector<std::string> written;
  std::string md = markdown_summary(results, o);
  nlohmann::json json = {{"throng_version", kVersion}, {"model", model_text(o)}, {"tests", nlohmann::json::array()}};
  bool missing_renderer = false;
  for (const VerifyResult& r : results) {
    const bool png = write_chart(dir, r);
    if (png) written.push_back(dir + "/" + png_name(r.number));
    missing_renderer = missing_renderer || (r.chart && !png);
    md += markdown_test(r, png);
    json["tests"].push_back(result_json(r, png));
  }
  if (missing_renderer)
    std::fprintf(stderr, "throng verify: this build has no renderer (-DTHRONG_RENDER=OFF): the report has no charts\n");
  io::write_text_file(dir + "/report.md", md);
  io::write_json_file(dir + "/report.json", json);
  written.insert(written.begin(), {dir + "/report.md", dir + "/report.json"});
  return written;
}

}  // namespace throng::app
