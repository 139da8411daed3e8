// `throng run`'s trajectory formats read back: one run written as CSV, PedPy
// text and JuPedSim SQLite at once, each file parsed from its published
// description (PedPy's load_trajectory_from_txt; JuPedSim's SQLite schema,
// version 2), and the positions compared with the CSV's.
#include "io/run_outputs.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "io/scenario_yaml.h"
#include "io/sqlite_trajectories.h"
#include "io/walkable_area.h"

namespace throng::io {
namespace {

namespace fs = std::filesystem;

// A 10 m square room with a pillar; 12 agents walk east for 23 steps of
// 0.1 s, written every 5 steps: frame rate 2, steps 0..20 on the stride and
// the last step 23 off it.
constexpr const char* kRoom = R"(planning: none
dt: 0.1
world:
  walkable: {polygon: [[0, 0], [10, 0], [10, 10], [0, 10]]}
  obstacles:
    - rect: {min: [4, 6], max: [6, 8]}
groups:
  - count: 12
    spawn: {rect: {min: [1, 1], max: [3, 4]}}
    goal: {point: [9, 2.5]}
)";
constexpr std::int64_t kEvery = 5, kSteps = 23;

using Key = std::pair<std::int64_t, std::int64_t>;  // (step, agent index)
using Positions = std::map<Key, std::pair<double, double>>;

class TrajectoryFormats : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / "throng_run_outputs_test";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const LoadedScenario loaded = parse_scenario(kRoom, "room.yaml");
    const std::unique_ptr<sim::Simulation> sim = build_simulation(loaded);
    sim::FrameLoop loop(*sim);
    wkt_ = to_wkt(walkable_area(*sim));
    for (TrajectoryFormat f : {TrajectoryFormat::Csv, TrajectoryFormat::Pedpy, TrajectoryFormat::Sqlite})
      loop.emplace<TrajectoryWriter>(TrajectoryOutput{f, path(f), kEvery, 0.1, wkt_});
    sim::RunControl control;
    control.max_steps = kSteps;
    control.stop_when_arrived = false;
    loop.run(control);
    loop.finish(stats_);
  }
  static std::string path(TrajectoryFormat f) { return (dir_ / trajectory_file_name(f)).string(); }

  // trajectories.csv: frame,time,agent,x,y,heading,speed.
  static Positions read_csv() {
    std::ifstream in(path(TrajectoryFormat::Csv));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, TrajectoryWriter::kHeader);
    Positions out;
    while (std::getline(in, line)) {
      std::replace(line.begin(), line.end(), ',', ' ');
      std::istringstream row(line);
      std::int64_t frame = 0, agent = 0;
      double time = 0, x = 0, y = 0;
      row >> frame >> time >> agent >> x >> y;
      EXPECT_FALSE(row.fail()) << line;
      out[{frame, agent}] = {x, y};
    }
    return out;
  }

  static inline fs::path dir_;
  static inline std::string wkt_;
  static inline nlohmann::json stats_;
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
  const Positions csv = read_csv();
  ASSERT_EQ(f.rows.size(), 5u * 12u);  // steps 0, 5, .., 20; the last step (23) is off the frame rate
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

// sqlite3 helpers for the checks below.
struct Db {
  sqlite3* db = nullptr;
  explicit Db(const std::string& path) { EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK); }
  ~Db() { sqlite3_close(db); }
  // Each row of a query as text columns.
  std::vector<std::vector<std::string>> query(const std::string& sql) const {
    std::vector<std::vector<std::string>> rows;
    sqlite3_stmt* s = nullptr;
    EXPECT_EQ(sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr), SQLITE_OK) << sql << ": " << sqlite3_errmsg(db);
    while (s != nullptr && sqlite3_step(s) == SQLITE_ROW) {
      std::vector<std::string> row;
      for (int c = 0; c < sqlite3_column_count(s); ++c) {
        const unsigned char* t = sqlite3_column_text(s, c);
        row.emplace_back(t != nullptr ? reinterpret_cast<const char*>(t) : "");
      }
      rows.push_back(std::move(row));
    }
    sqlite3_finalize(s);
    return rows;
  }
  std::string one(const std::string& sql) const {
    const auto rows = query(sql);
    return rows.empty() || rows[0].empty() ? std::string("<none>") : rows[0][0];
  }
};

// Rings of a WKT "POLYGON ((x y, ...), ...)", each checked closed; empty when
// the text is not one polygon.
std::vector<std::vector<std::pair<double, double>>> parse_wkt_polygon(const std::string& wkt) {
  std::vector<std::vector<std::pair<double, double>>> rings;
  const std::string head = "POLYGON (";
  if (!wkt.starts_with(head) || !wkt.ends_with(")")) return {};
  std::string body = wkt.substr(head.size(), wkt.size() - head.size() - 1);
  std::size_t at = 0;
  while (at < body.size()) {
    const std::size_t open = body.find('(', at), close = body.find(')', at);
    if (open == std::string::npos || close == std::string::npos || close < open) return {};
    std::string ring = body.substr(open + 1, close - open - 1);
    std::replace(ring.begin(), ring.end(), ',', ' ');
    std::istringstream points(ring);
    std::vector<std::pair<double, double>> pts;
    for (double x, y; points >> x >> y;) pts.emplace_back(x, y);
    if (!points.eof() || pts.size() < 4 || pts.front() != pts.back()) return {};
    rings.push_back(std::move(pts));
    at = body.find_first_not_of(", ", close + 1);
    if (at == std::string::npos) break;
  }
  return rings;
}

TEST_F(TrajectoryFormats, SqliteFollowsJupedsimSchemaVersion2) {
  const Db db(path(TrajectoryFormat::Sqlite));
  EXPECT_EQ(db.one("SELECT value FROM metadata WHERE key = 'version'"), "2");
  EXPECT_EQ(std::stod(db.one("SELECT value FROM metadata WHERE key = 'fps'")), 2.0);
  EXPECT_EQ(db.one("SELECT value FROM metadata WHERE key = 'xmin'"), "0");
  EXPECT_EQ(db.one("SELECT value FROM metadata WHERE key = 'ymax'"), "10");
  EXPECT_EQ(db.one("SELECT count(*) FROM trajectory_data"), "60");
  EXPECT_EQ(db.one("SELECT count(*) FROM frame_data"), "5");
  EXPECT_EQ(db.one("SELECT count(DISTINCT geometry_hash) FROM frame_data"), "1");
  EXPECT_EQ(db.one("SELECT min(id) || ' ' || max(id) FROM trajectory_data"), "1 12");
  // The frame's geometry is the stored one (what JuPedSim's readers join on).
  EXPECT_EQ(db.one("SELECT count(*) FROM frame_data JOIN geometry ON frame_data.geometry_hash = geometry.hash"), "5");
  // Orientation: unit vectors.
  EXPECT_EQ(db.one("SELECT count(*) FROM trajectory_data WHERE abs(ori_x * ori_x + ori_y * ori_y - 1) > 1e-6"), "0");

  const Positions csv = read_csv();
  for (const auto& row : db.query("SELECT frame, id, pos_x, pos_y FROM trajectory_data")) {
    const auto it = csv.find({std::stoll(row[0]) * kEvery, std::stoll(row[1]) - 1});
    ASSERT_NE(it, csv.end()) << row[0] << " " << row[1];
    EXPECT_NEAR(std::stod(row[2]), it->second.first, 5.1e-5);  // CSV rounds to 0.1 mm
    EXPECT_NEAR(std::stod(row[3]), it->second.second, 5.1e-5);
  }

  const std::string wkt = db.one("SELECT wkt FROM geometry");
  EXPECT_EQ(wkt, wkt_);
  const auto rings = parse_wkt_polygon(wkt);
  ASSERT_EQ(rings.size(), 2u) << wkt;  // the room and the pillar
  EXPECT_EQ(rings[0].size(), 5u);
  EXPECT_EQ(rings[1].size(), 5u);
}

TEST_F(TrajectoryFormats, StatsNameTheFormatAndFile) {
  const nlohmann::json& t = stats_["trajectories"];  // the last writer added: sqlite
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
    EXPECT_EQ(e.message(), "unknown trajectory format 'sqlite3': expected csv, pedpy or sqlite (did you mean 'sqlite'?)");
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
