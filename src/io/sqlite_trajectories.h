// Trajectories in JuPedSim's SQLite format, database version 2: what
// jupedsim.SqliteTrajectoryWriter wrote before version 3 dropped the
// orientation, what pedpy.load_trajectory_from_jupedsim_sqlite and
// pedpy.load_walkable_area_from_jupedsim_sqlite read (PedPy reads versions
// 1 and 2; JuPedSim upgrades 2 to 3 in place). Tables:
//   metadata(key TEXT UNIQUE PRIMARY KEY, value TEXT)
//       version = 2, fps, xmin, xmax, ymin, ymax (the geometry's bounds)
//   geometry(hash INTEGER, wkt TEXT)          one row: the walkable area
//   frame_data(frame INTEGER, geometry_hash INTEGER)   one row per frame
//   trajectory_data(frame, id, pos_x, pos_y, ori_x, ori_y)
// with frame = step / every (time = frame / fps), id = agent index + 1 and
// (ori_x, ori_y) the unit heading vector.
//
// Each frame is one transaction of prepared inserts, so an interrupted run
// leaves a database of complete frames: a process killed mid-frame leaves a
// rollback journal that the next reader's open undoes.
#pragma once

#include <string>

#include "io/run_outputs.h"

struct sqlite3;
struct sqlite3_stmt;

namespace throng::io {

class SqliteTrajectorySink final : public TrajectorySink {
 public:
  static constexpr int kVersion = 2;

  // Replaces `path`; creates the tables; stores fps and the geometry.
  SqliteTrajectorySink(std::string path, double fps, const std::string& geometry_wkt);
  ~SqliteTrajectorySink() override;
  SqliteTrajectorySink(const SqliteTrajectorySink&) = delete;
  SqliteTrajectorySink& operator=(const SqliteTrajectorySink&) = delete;

  void write(const TrajectoryFrame& frame) override;
  void close() override;
  bool uniform_frames() const override { return true; }
  std::string columns() const override { return "trajectory_data(frame, id, pos_x, pos_y, ori_x, ori_y)"; }
  void describe(nlohmann::json& section) const override;

 private:
  void exec(const char* sql);
  sqlite3_stmt* prepare(const char* sql);
  [[noreturn]] void fail(const std::string& what) const;
  void create_schema(const std::string& geometry_wkt);

  std::string path_;
  double fps_;
  std::int64_t geometry_hash_ = 0;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_row_ = nullptr;
  sqlite3_stmt* insert_frame_ = nullptr;
};

}  // namespace throng::io
