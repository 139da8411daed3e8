// `throng run`'s trajectory writer: the PedPy text file of a run read back
// as PedPy's load_trajectory_from_txt reads it, its positions compared with
// the CSV of the same run; stats; the format names shared by YAML and CLI.
// (The SQLite file of the same run: sqlite_trajectories_test.cpp.)
#include "io/run_outputs.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <tuple>

#include "io/sqlite_trajectories.h"
#include "tests/io/trajectory_run.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;
using namespace throng::io::testing;

class TrajectoryFormats : public ::testing::Test {
 protected:
  // One folder per process: ctest runs each test of the suite in a process
  // of its own, two at a time, and two runs writing one SQLite file clash
  // ("attempt to write a readonly database").
  static void SetUpTestSuite() {
    run_ = run_room(fs::temp_directory_path() / ("throng_run_outputs_test_" + std::to_string(::getpid())));
  }
  static void TearDownTestSuite() { fs::remove_all(run_.dir); }
  static std::string path(TrajectoryFormat f) { return run_.path(f); }
  static inline RoomRun run_;
};

// PedPy's reader, after pedpy/io/trajectory_loader.py: the leading lines
// starting with '#' are the header; a header line containing "framerate"
// gives the frame rate (its first number), one containing "x/m" or "in m"
// says metres (and "x/cm" or "in cm" centimetres); then rows of whitespace-
// separated columns id frame x y [z ...], where '#' starts a comment.
struct PedpyFile {
  std::optional<double> framerate;
  std::optional<std::string> unit;
  std::vector<std::tuple<std::int64_t, std::int64_t, double, double>> rows;  // id, frame, x, y
};
PedpyFile read_pedpy(const std::string& path) {
  PedpyFile f;
  std::ifstream in(path);
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    header = header && line.starts_with('#');
    if (header) {
      std::string lower = line;
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
      if (lower.find("framerate") != std::string::npos && !f.framerate) {
        std::istringstream words(line);
        for (std::string w; words >> w && !f.framerate;) {
          char* end = nullptr;
          const double v = std::strtod(w.c_str(), &end);
          if (end != w.c_str() && *end == '\0') f.framerate = v;
        }
      }
      if (lower.find("x/cm") != std::string::npos || lower.find("in cm") != std::string::npos) f.unit = "cm";
      if (lower.find("x/m") != std::string::npos || lower.find("in m") != std::string::npos) f.unit = "m";
      continue;
    }
    line = line.substr(0, line.find('#'));
    std::istringstream row(line);
    std::int64_t id = 0, frame = 0;
    double x = 0, y = 0;
    if (!(row >> id >> frame >> x >> y)) {
      EXPECT_TRUE(line.find_first_not_of(" \t\r") == std::string::npos) << "unreadable row: " << line;
      continue;
    }
    f.rows.emplace_back(id, frame, x, y);
  }
  return f;
}

TEST_F(TrajectoryFormats, PedpyTextReadsBackAsTheCsvPositions) {
  const PedpyFile f = read_pedpy(path(TrajectoryFormat::Pedpy));
  ASSERT_TRUE(f.framerate.has_value());
  EXPECT_EQ(*f.framerate, 2.0);  // 1 / (0.1 s * 5)
  EXPECT_EQ(f.unit, "m");
  const Positions csv = read_csv(path(TrajectoryFormat::Csv));
  ASSERT_EQ(f.rows.size(),
            5u * static_cast<std::size_t>(kAgents));  // steps 0, 5, .., 20; the last step (23) is off the frame rate
  std::map<std::int64_t, int> per_frame;
  for (const auto& [id, frame, x, y] : f.rows) {
    EXPECT_GE(id, 1);
    ++per_frame[frame];
    const auto it = csv.find({frame * kEvery, id - 1});
    ASSERT_NE(it, csv.end()) << "id " << id << " frame " << frame;
    EXPECT_EQ(x, it->second.first);  // both printed with 4 decimals
    EXPECT_EQ(y, it->second.second);
  }
  EXPECT_EQ(per_frame, (std::map<std::int64_t, int>{{0, 12}, {1, 12}, {2, 12}, {3, 12}, {4, 12}}));
  EXPECT_EQ(csv.size(), 6u * 12u);  // CSV also has the last step
  EXPECT_EQ(csv.count({kSteps, 0}), 1u);
}

TEST_F(TrajectoryFormats, StatsNameTheFormatAndFile) {
  const nlohmann::json& t = run_.stats["trajectories"];  // the last writer added: sqlite
  EXPECT_EQ(t["format"], "sqlite");
  EXPECT_EQ(t["path"], path(TrajectoryFormat::Sqlite));
  EXPECT_EQ(t["frames"], 5);
  EXPECT_EQ(t["rows"], 60);
  EXPECT_EQ(t["framerate"], 2.0);
  EXPECT_EQ(t["sqlite_version"], SqliteTrajectorySink::kVersion);
}

TEST(TrajectoryFormat, NamesAreCheckedOnceForYamlAndCli) {
  EXPECT_EQ(parse_trajectory_format("csv", "f"), TrajectoryFormat::Csv);
  EXPECT_EQ(parse_trajectory_format("pedpy", "f"), TrajectoryFormat::Pedpy);
  EXPECT_EQ(parse_trajectory_format("sqlite", "f"), TrajectoryFormat::Sqlite);
  try {
    parse_trajectory_format("sqlite3", "--trajectory-format");
    FAIL() << "accepted sqlite3";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().field, "--trajectory-format");
    EXPECT_EQ(e.message(),
              "unknown trajectory format 'sqlite3': expected csv, pedpy or sqlite (did you mean 'sqlite'?)");
  }
  EXPECT_EQ(trajectory_file_name(TrajectoryFormat::Pedpy), "trajectories.txt");
  EXPECT_EQ(trajectory_file_name(TrajectoryFormat::Sqlite), "trajectories.sqlite");
}

TEST(TrajectoryFormat, FrameRateReadsAsTyped) {
  EXPECT_EQ(trajectory_frame_rate(static_cast<double>(0.1f), 10), 1.0);
  EXPECT_EQ(trajectory_frame_rate(static_cast<double>(0.05f), 1), 20.0);
  EXPECT_EQ(trajectory_frame_rate(static_cast<double>(0.04f), 3), 8.33333);
}

}  // namespace
}  // namespace throng::io
