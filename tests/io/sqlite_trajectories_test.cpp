// JuPedSim's SQLite trajectory format, database version 2, read back with
// sqlite3 queries: the room run of trajectory_run.h (written as CSV too),
// metadata, row counts, positions against the CSV, the geometry as WKT.
#include "io/sqlite_trajectories.h"

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "tests/io/trajectory_run.h"

namespace throng::io {
namespace {

using namespace throng::io::testing;

// sqlite3 helpers for the checks below.
struct Db {
  sqlite3* db = nullptr;
  explicit Db(const std::string& path) {
    EXPECT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
  }
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

TEST(SqliteTrajectories, FollowJupedsimSchemaVersion2) {
  const RoomRun run = run_room(std::filesystem::temp_directory_path() / "throng_sqlite_trajectories_test");
  const Db db(run.path(TrajectoryFormat::Sqlite));
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

  const Positions csv = read_csv(run.path(TrajectoryFormat::Csv));
  for (const auto& row : db.query("SELECT frame, id, pos_x, pos_y FROM trajectory_data")) {
    const auto it = csv.find({std::stoll(row[0]) * kEvery, std::stoll(row[1]) - 1});
    ASSERT_NE(it, csv.end()) << row[0] << " " << row[1];
    EXPECT_NEAR(std::stod(row[2]), it->second.first, 5.1e-5);  // CSV rounds to 0.1 mm
    EXPECT_NEAR(std::stod(row[3]), it->second.second, 5.1e-5);
  }

  const std::string wkt = db.one("SELECT wkt FROM geometry");
  EXPECT_EQ(wkt, run.wkt);
  const auto rings = parse_wkt_polygon(wkt);
  ASSERT_EQ(rings.size(), 2u) << wkt;  // the room and the pillar
  EXPECT_EQ(rings[0].size(), 5u);
  EXPECT_EQ(rings[1].size(), 5u);
}

}  // namespace
}  // namespace throng::io
