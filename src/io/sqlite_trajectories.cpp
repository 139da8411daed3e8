#include "io/sqlite_trajectories.h"

#include <fmt/format.h>
#include <sqlite3.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"

namespace throng::io {

namespace {

// The geometry table's key. JuPedSim uses Python's hash() of the WKT, which
// no reader recomputes: any integer that frame_data repeats will do. FNV-1a,
// kept within SQLite's signed 64-bit INTEGER.
std::int64_t wkt_hash(const std::string& wkt) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : wkt) h = (h ^ c) * 1099511628211ull;
  return static_cast<std::int64_t>(h >> 1);
}

// Bounds of the numbers in a WKT text, read back from the text itself so the
// metadata agrees with the stored geometry to the digit.
struct Bounds {
  double xmin = std::numeric_limits<double>::infinity(), ymin = xmin, xmax = -xmin, ymax = -xmin;
};
Bounds wkt_bounds(const std::string& wkt) {
  Bounds b;
  const char* s = wkt.c_str();
  bool is_x = true;
  while (*s != '\0') {
    char* end = nullptr;
    const double v = (*s == '-' || (*s >= '0' && *s <= '9')) ? std::strtod(s, &end) : 0.0;
    if (end == nullptr || end == s) {
      ++s;
      continue;
    }
    (is_x ? b.xmin : b.ymin) = std::fmin(is_x ? b.xmin : b.ymin, v);
    (is_x ? b.xmax : b.ymax) = std::fmax(is_x ? b.xmax : b.ymax, v);
    is_x = !is_x;
    s = end;
  }
  return b;
}

}  // namespace

SqliteTrajectorySink::SqliteTrajectorySink(std::string path, double fps, const std::string& geometry_wkt)
    : path_(std::move(path)), fps_(fps), geometry_hash_(wkt_hash(geometry_wkt)) {
  std::error_code ec;
  std::filesystem::remove(path_, ec);  // a fresh database, as JuPedSim drops its tables
  std::filesystem::remove(path_ + "-journal", ec);
  if (sqlite3_open_v2(path_.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK)
    fail("cannot open");
  // A rollback journal keeps every committed frame readable after a crash
  // of the process; not waiting for the disk (synchronous off) only risks
  // frames on a crash of the machine.
  exec("PRAGMA synchronous=OFF");
  exec("PRAGMA journal_mode=DELETE");
  create_schema(geometry_wkt);
  insert_row_ = prepare("INSERT INTO trajectory_data VALUES(?, ?, ?, ?, ?, ?)");
  insert_frame_ = prepare("INSERT INTO frame_data VALUES(?, ?)");
}

SqliteTrajectorySink::~SqliteTrajectorySink() {
  sqlite3_finalize(insert_row_);
  sqlite3_finalize(insert_frame_);
  if (db_ != nullptr) sqlite3_close(db_);
}

void SqliteTrajectorySink::create_schema(const std::string& geometry_wkt) {
  exec("BEGIN");
  exec("CREATE TABLE metadata(key TEXT NOT NULL UNIQUE PRIMARY KEY, value TEXT NOT NULL)");
  exec("CREATE TABLE geometry(hash INTEGER NOT NULL, wkt TEXT NOT NULL)");
  exec("CREATE UNIQUE INDEX geometry_hash ON geometry(hash)");
  exec("CREATE TABLE frame_data(frame INTEGER NOT NULL, geometry_hash INTEGER NOT NULL)");
  exec(
      "CREATE TABLE trajectory_data(frame INTEGER NOT NULL, id INTEGER NOT NULL, pos_x REAL NOT NULL, pos_y REAL NOT "
      "NULL, "
      "ori_x REAL NOT NULL, ori_y REAL NOT NULL)");
  exec("CREATE INDEX frame_id_idx ON trajectory_data(frame, id)");
  const Bounds b = wkt_bounds(geometry_wkt);
  sqlite3_stmt* meta = prepare("INSERT INTO metadata VALUES(?, ?)");
  const std::pair<const char*, std::string> entries[] = {
      {"version", std::to_string(kVersion)}, {"fps", fmt::format("{}", fps_)},    {"xmin", fmt::format("{}", b.xmin)},
      {"xmax", fmt::format("{}", b.xmax)},   {"ymin", fmt::format("{}", b.ymin)}, {"ymax", fmt::format("{}", b.ymax)}};
  for (const auto& [key, value] : entries) {
    sqlite3_bind_text(meta, 1, key, -1, SQLITE_STATIC);
    sqlite3_bind_text(meta, 2, value.c_str(), -1, SQLITE_TRANSIENT);
    const int rc = sqlite3_step(meta);
    sqlite3_reset(meta);
    if (rc != SQLITE_DONE) {
      sqlite3_finalize(meta);
      fail("cannot store the metadata");
    }
  }
  sqlite3_finalize(meta);
  sqlite3_stmt* geo = prepare("INSERT INTO geometry VALUES(?, ?)");
  sqlite3_bind_int64(geo, 1, geometry_hash_);
  sqlite3_bind_text(geo, 2, geometry_wkt.c_str(), -1, SQLITE_TRANSIENT);
  const int rc = sqlite3_step(geo);
  sqlite3_finalize(geo);
  if (rc != SQLITE_DONE) fail("cannot store the geometry");
  exec("COMMIT");
}

void SqliteTrajectorySink::write(const TrajectoryFrame& f) {
  exec("BEGIN");
  for (const TrajectoryRow& r : f.rows) {
    sqlite3_bind_int64(insert_row_, 1, f.index);
    sqlite3_bind_int64(insert_row_, 2, r.agent + 1);
    sqlite3_bind_double(insert_row_, 3, r.x);
    sqlite3_bind_double(insert_row_, 4, r.y);
    sqlite3_bind_double(insert_row_, 5, std::cos(static_cast<double>(r.heading)));
    sqlite3_bind_double(insert_row_, 6, std::sin(static_cast<double>(r.heading)));
    const int rc = sqlite3_step(insert_row_);
    sqlite3_reset(insert_row_);
    if (rc != SQLITE_DONE) fail("cannot store a trajectory row");
  }
  sqlite3_bind_int64(insert_frame_, 1, f.index);
  sqlite3_bind_int64(insert_frame_, 2, geometry_hash_);
  const int rc = sqlite3_step(insert_frame_);
  sqlite3_reset(insert_frame_);
  if (rc != SQLITE_DONE) fail("cannot store a frame");
  exec("COMMIT");
}

void SqliteTrajectorySink::close() {
  if (db_ == nullptr) return;
  sqlite3_finalize(insert_row_);
  sqlite3_finalize(insert_frame_);
  insert_row_ = insert_frame_ = nullptr;
  const int rc = sqlite3_close(db_);
  db_ = nullptr;
  if (rc != SQLITE_OK) throw Error("closing the database failed", Location{path_, 0, 0, {}});
}

void SqliteTrajectorySink::describe(nlohmann::json& section) const {
  section["framerate"] = fps_;
  section["sqlite_version"] = kVersion;
}

void SqliteTrajectorySink::exec(const char* sql) {
  char* message = nullptr;
  if (sqlite3_exec(db_, sql, nullptr, nullptr, &message) != SQLITE_OK) {
    const std::string what = message != nullptr ? message : "unknown error";
    sqlite3_free(message);
    throw Error(fmt::format("SQLite: {} ({})", what, sql), Location{path_, 0, 0, {}});
  }
}

sqlite3_stmt* SqliteTrajectorySink::prepare(const char* sql) {
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db_, sql, -1, &s, nullptr) != SQLITE_OK) fail(std::string("cannot prepare ") + sql);
  return s;
}

void SqliteTrajectorySink::fail(const std::string& what) const {
  throw Error(fmt::format("SQLite: {}: {}", what, db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory"),
              Location{path_, 0, 0, {}});
}

}  // namespace throng::io
