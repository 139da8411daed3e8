// throng verify: runs the RiMEA 3.0 verification tests (app/verification.h)
// and writes their report; exits 1 when an applicable test fails.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/verification.h"
#include "core/error.h"

namespace throng::app {

namespace {

struct VerifyCommandOptions {
  std::string out = "out/verify";
  std::vector<int> only;
  std::string model;
  bool list = false;
};

void list_tests() {
  for (const VerifyTest& t : verification_tests())
    std::printf("%2d  %s%s\n", t.number, t.title.c_str(), t.run ? "" : "  (not applicable)");
}

void verify(const VerifyCommandOptions& c) {
  if (c.list) return list_tests();
  VerifyOptions o;
  o.only = c.only;
  if (!c.model.empty()) o.model = sim::parse_model_kind(c.model, "--model");
  const std::vector<VerifyResult> results = run_verification(o);
  const std::vector<std::string> written = write_verification_report(c.out, results, o);
  int pass = 0, fail = 0, na = 0;
  for (const VerifyResult& r : results) {
    (r.status == VerifyStatus::pass ? pass : r.status == VerifyStatus::fail ? fail : na) += 1;
    std::printf("test %2d  %-15s %s\n", r.number, to_string(r.status), r.title.c_str());
  }
  std::printf("%d passed, %d failed, %d not applicable; report: %s\n", pass, fail, na, written.front().c_str());
  std::fflush(stdout);
  if (fail > 0) std::exit(1);
}

}  // namespace

void add_verify_command(CLI::App& app, const GlobalOptions& g) {
  auto* cmd = app.add_subcommand("verify",
                                 "Run the RiMEA 3.0 verification tests (docs/verification.md) and write a report "
                                 "(report.md, report.json, one PNG chart per test); exit status 1 when a test fails");
  static VerifyCommandOptions o;
  cmd->add_option("--out", o.out, "Output folder")->capture_default_str();
  cmd->add_option("--only", o.only, "Run only these tests (numbers 1 to 15, e.g. --only 1,4,9)")->delimiter(',');
  cmd->add_option("--model", o.model,
                  "Steering model for every test (priority, collision_free_speed, ttc, social_force); default: as "
                  "the scenario files say, the engine's default");
  cmd->add_flag("--list", o.list, "List the tests and exit");
  cmd->callback([&g] {
    apply_global_options(g);
    verify(o);
  });
}

}  // namespace throng::app
