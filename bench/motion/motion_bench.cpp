// Motion data: BVH parse and write speed (bytes/s in the items/s column) on
// the largest shared mocap file, and forward kinematics throughput
// (joints/s) for many characters, each at its own frame of a clip.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench/registry.h"
#include "core/exec.h"
#include "core/buffer.h"
#include "io/bvh_reader.h"
#include "io/bvh_writer.h"
#include "motion/fk_batch.h"
#include "motion/motion_texture.h"

namespace throng::bench {

namespace {

namespace fs = std::filesystem;

// THRONG_SHARED_DIR, else ../shared beside the source tree; empty if absent.
fs::path largest_shared_bvh() {
  std::vector<fs::path> roots;
  if (const char* env = std::getenv("THRONG_SHARED_DIR")) roots.emplace_back(env);
  roots.push_back(fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path() / "shared");
  for (const auto& root : roots) {
    const fs::path dir = root / "data" / "bvh";
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) continue;
    fs::path best;
    std::uintmax_t best_size = 0;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".bvh" && e.file_size() > best_size) {
        best_size = e.file_size();
        best = e.path();
      }
    if (!best.empty()) return best;
  }
  return {};
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A 31-joint tree (the CMU skeleton's size: six chains of five joints from
// the root) and a clip of random rotations.
struct Character {
  motion::Skeleton skeleton;
  motion::Clip clip;
};
Character make_character(int joints, int frames) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  Character c;
  for (int j = 0; j < joints; ++j) {
    const std::int32_t parent = j == 0 ? -1 : (j % 5 == 1 ? 0 : j - 1);
    std::string name = "j";  // appended: GCC 12 warns falsely (-Wrestrict) on "j" + std::string
    name.append(std::to_string(j));
    c.skeleton.add_joint(name, parent, glm::vec3(0.0f, 0.1f, 0.02f));
  }
  c.clip.resize(frames, joints);
  for (auto& q : c.clip.rotations) q = glm::normalize(glm::quat(g(rng), g(rng), g(rng), g(rng)));
  for (auto& p : c.clip.root_positions) p = glm::vec3(g(rng), 1.0f, g(rng));
  return c;
}

void register_motion(const Options& options) {
  const fs::path bvh = largest_shared_bvh();
  if (!bvh.empty()) {
    const auto bytes = static_cast<Index>(fs::file_size(bvh));
    add(options, {"motion/bvh_parse",
                  {bytes},
                  [bvh](benchmark::State& state, Index n) {
                    const std::string text = slurp(bvh);
                    for (auto _ : state) benchmark::DoNotOptimize(io::parse_bvh(text, bvh.string()));
                    state.SetBytesProcessed(state.iterations() * n);
                    state.SetItemsProcessed(state.iterations() * n);  // items/s column = bytes/s
                  },
                  false,
                  true});
    add(options, {"motion/bvh_write",
                  {bytes},
                  [bvh](benchmark::State& state, Index) {
                    const io::BvhFile file = io::read_bvh(bvh.string());
                    std::size_t written = 0;
                    for (auto _ : state) {
                      const std::string out = io::write_bvh_string(file.skeleton, file.clip);
                      written = out.size();
                      benchmark::DoNotOptimize(out.data());
                    }
                    state.SetItemsProcessed(state.iterations() * static_cast<Index>(written));  // bytes written/s
                  },
                  false,
                  true});
  }

  // FK for N characters, each at its own frame: items = characters * joints.
  add(options, {"motion/fk_batch_31j",
                {10000, 100000},
                [](benchmark::State& state, Index n) {
                  const Character c = make_character(31, 120);
                  const Memory m = current_memory();
                  std::vector<std::int32_t> frames(static_cast<std::size_t>(n));
                  for (std::size_t i = 0; i < frames.size(); ++i)
                    frames[i] = static_cast<std::int32_t>((i * 7919) % 120);
                  const Buffer<std::int32_t> parents(std::span<const std::int32_t>(c.skeleton.parents), m);
                  const Buffer<glm::vec3> offsets(std::span<const glm::vec3>(c.skeleton.offsets), m);
                  const Buffer<glm::quat> rotations(std::span<const glm::quat>(c.clip.rotations), m);
                  const Buffer<glm::vec3> roots(std::span<const glm::vec3>(c.clip.root_positions), m);
                  const Buffer<std::int32_t> frame_of(std::span<const std::int32_t>(frames), m);
                  Buffer<glm::vec3> out_p(n * 31, m);
                  Buffer<glm::quat> out_r(n * 31, m);
                  motion::BatchFkJob job;
                  job.joint_count = 31;
                  job.frame_count = 120;
                  job.parents = parents.span();
                  job.offsets = offsets.span();
                  job.clip_rotations = rotations.span();
                  job.clip_roots = roots.span();
                  job.frames = frame_of.span();
                  job.out_positions = out_p.span();
                  job.out_rotations = out_r.span();
                  for (auto _ : state) {
                    job.run();
                    finish_device_work();
                  }
                  state.SetItemsProcessed(state.iterations() * n * 31);
                },
                true});

  // FK of every row of an fp16 motion texture: items = frames * joints.
  add(options, {"motion/fk_texture_f16_31j", {1000, 10000}, [](benchmark::State& state, Index n) {
                  const Character c = make_character(31, static_cast<int>(n));
                  const motion::MotionTexture t =
                      motion::make_motion_texture(c.skeleton, c.clip, motion::TexelFormat::Float16);
                  for (auto _ : state) benchmark::DoNotOptimize(motion::forward_kinematics(t));
                  state.SetItemsProcessed(state.iterations() * n * 31);
                }});
}

}  // namespace

static const bool registered = register_suite("motion", &register_motion);

}  // namespace throng::bench
