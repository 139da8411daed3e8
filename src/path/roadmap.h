// The topology layer: a roadmap on the medial axis of free space.
//
// The generalised Voronoi diagram of the free space's boundary segments
// (Boost.Polygon, exact predicates on the snapped integer geometry) holds,
// inside free space, the points equidistant from two or more obstacles: the
// medial axis. Its edges are straight (two segments or two points) or
// parabolic (a point and a segment); parabolic arcs become polylines within
// `arc_tolerance`. Every polyline point carries its clearance (distance to
// the nearest obstacle, exact: the distance to the edge's Voronoi sites).
// Pieces with clearance below `radius + margin` are cut away, so the graph
// holds exactly the part of the medial axis a disc of that radius can use;
// since free space retracts onto its medial axis, any point where the disc
// fits is joined to the graph by a straight collision-free segment.
#pragma once

#include <cstdint>
#include <glm/vec2.hpp>
#include <vector>

#include "path/free_space.h"

namespace throng::path {

struct RoadmapOptions {
  float radius = 0.25f;          // m: the agent's radius; edges keep at least this clearance
  float arc_tolerance = 0.001f;  // m: largest gap between a parabolic arc and its polyline
  float max_step = 0.5f;         // m: longest polyline piece (clearance sampled at least this often)
  void validate() const;         // throws Error naming the field
  // Clearance the kept edges have, at least: radius plus the snapping error
  // (resolution) and the arc tolerance, so the true clearance is >= radius.
  float kept_clearance(float resolution) const { return radius + resolution + arc_tolerance; }
};

struct RoadmapEdge {
  std::int32_t a = 0, b = 0;     // node indices
  std::int32_t point_begin = 0;  // polyline points [point_begin, point_begin + point_count), from a to b
  std::int32_t point_count = 0;
  float length = 0.0f;         // m
  float min_clearance = 0.0f;  // m
};

// A point on an edge: polyline piece `piece` (from point piece to piece + 1)
// at parameter t in [0, 1].
struct EdgePoint {
  std::int32_t edge = -1;
  std::int32_t piece = 0;
  float t = 0.0f;
  glm::vec2 point{0.0f};
  float distance = INFINITY;  // from the query point
};

struct Roadmap {
  RoadmapOptions options;
  std::vector<glm::vec2> nodes;
  std::vector<float> node_clearance;
  std::vector<RoadmapEdge> edges;
  std::vector<glm::vec2> points;       // every edge's polyline, edge after edge
  std::vector<float> point_clearance;  // clearance at each polyline point
  // Adjacency (CSR): the edges at node n are adjacency[adjacency_begin[n] .. adjacency_begin[n + 1]).
  std::vector<std::int32_t> adjacency_begin;
  std::vector<std::int32_t> adjacency;
  std::vector<std::int32_t> node_component;  // connected component of each node

  // Statistics of the build.
  std::int64_t voronoi_edges = 0;  // finite primary edges of the diagram
  std::int64_t inside_edges = 0;   // of those, in free space

  std::int32_t node_count() const { return static_cast<std::int32_t>(nodes.size()); }
  std::int32_t edge_count() const { return static_cast<std::int32_t>(edges.size()); }
  glm::vec2 edge_point(std::int32_t edge, std::int32_t i) const {
    return points[static_cast<std::size_t>(edges[static_cast<std::size_t>(edge)].point_begin + i)];
  }
  // The nearest points of the roadmap to p, one per edge, nearest first (ties
  // by edge index), at most `limit` of them. Searches the piece index ring
  // by ring outwards from p, so the cost follows the roadmap near p, not the
  // whole roadmap (see nearest_points_brute_force, the reference).
  std::vector<EdgePoint> nearest_points(glm::vec2 p, std::int32_t limit) const;
  // The same by a scan of every edge.
  std::vector<EdgePoint> nearest_points_brute_force(glm::vec2 p, std::int32_t limit) const;

  // The piece index: every polyline piece (points k, k + 1 of one edge,
  // named by k) registered in the cells its bounding box touches.
  // build_roadmap makes it; index_pieces() remakes it after the points change.
  void index_pieces();
  float index_cell = 1.0f;               // m
  sim::Aabb index_bounds;                // of every point
  std::vector<std::int32_t> point_edge;  // the edge each point belongs to
  sim::StaticGrid piece_index;
};

// Builds the roadmap of `space` for discs of options.radius.
Roadmap build_roadmap(const FreeSpace& space, const RoadmapOptions& options);

}  // namespace throng::path
