#include "io/crowd_gltf.h"

#include <tiny_gltf.h>

#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <utility>

#include "core/error.h"
#include "core/output_file.h"

namespace throng::io {

namespace {

Location in_file(const std::string& path, std::string field = {}) { return Location{path, 0, 0, std::move(field)}; }

// Appends typed arrays to the model's one buffer, each as a buffer view
// (4-byte aligned), and describes them with accessors.
class GlbBuilder {
 public:
  explicit GlbBuilder(tinygltf::Model& m) : m_(m) { m_.buffers.resize(1); }

  int view(const void* bytes, std::size_t size, int target = 0) {
    std::vector<unsigned char>& data = m_.buffers[0].data;
    while (data.size() % 4 != 0) data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = data.size();
    v.byteLength = size;
    if (target != 0) v.target = target;
    const auto* b = static_cast<const unsigned char*>(bytes);
    data.insert(data.end(), b, b + size);
    m_.bufferViews.push_back(v);
    return static_cast<int>(m_.bufferViews.size()) - 1;
  }

  int accessor(int view, std::size_t offset, int component, int type, std::size_t count, std::vector<double> min = {},
               std::vector<double> max = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = offset;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    m_.accessors.push_back(a);
    return static_cast<int>(m_.accessors.size()) - 1;
  }

 private:
  tinygltf::Model& m_;
};

std::vector<double> to_doubles(const glm::vec3& v) { return {v.x, v.y, v.z}; }
std::vector<double> to_doubles(const glm::quat& q) { return {q.x, q.y, q.z, q.w}; }  // glTF: x, y, z, w

// The mesh as primitive attributes: POSITION (with bounds), NORMAL,
// JOINTS_0, WEIGHTS_0, and the triangle indices.
int add_mesh(tinygltf::Model& m, GlbBuilder& b, const anim::SkinnedMesh& mesh) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const std::size_t n = mesh.positions.size();
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] =
      b.accessor(b.view(mesh.positions.data(), n * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER), 0,
                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, to_doubles(lo), to_doubles(hi));
  prim.attributes["NORMAL"] =
      b.accessor(b.view(mesh.normals.data(), n * sizeof(glm::vec3), TINYGLTF_TARGET_ARRAY_BUFFER), 0,
                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
  prim.attributes["JOINTS_0"] =
      b.accessor(b.view(mesh.joints.data(), n * sizeof(glm::u16vec4), TINYGLTF_TARGET_ARRAY_BUFFER), 0,
                 TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, n);
  prim.attributes["WEIGHTS_0"] =
      b.accessor(b.view(mesh.weights.data(), n * sizeof(glm::vec4), TINYGLTF_TARGET_ARRAY_BUFFER), 0,
                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, n);
  prim.indices = b.accessor(
      b.view(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER), 0,
      TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, mesh.indices.size());
  tinygltf::Material material;
  material.name = "mannequin";
  material.pbrMetallicRoughness.baseColorFactor = {0.55, 0.6, 0.7, 1.0};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.8;
  m.materials.push_back(material);
  prim.material = 0;
  tinygltf::Mesh gm;
  gm.name = "mannequin";
  gm.primitives.push_back(prim);
  m.meshes.push_back(gm);
  return 0;
}

// The inverse bind matrices (column-major 4x4), shared by every skin.
int add_inverse_bind(GlbBuilder& b, const anim::Rig& rig) {
  std::vector<float> mats;
  for (const anim::Mat3x4& x : rig.inverse_bind) {
    const float cols[16] = {x.r0.x, x.r1.x, x.r2.x, 0.0f, x.r0.y, x.r1.y, x.r2.y, 0.0f,
                            x.r0.z, x.r1.z, x.r2.z, 0.0f, x.r0.w, x.r1.w, x.r2.w, 1.0f};
    mats.insert(mats.end(), cols, cols + 16);
  }
  return b.accessor(b.view(mats.data(), mats.size() * sizeof(float)), 0, TINYGLTF_COMPONENT_TYPE_FLOAT,
                    TINYGLTF_TYPE_MAT4, rig.inverse_bind.size());
}

// Agent a's joint nodes, mesh node and skin; its keys go into `anim`.
void add_agent(tinygltf::Model& m, GlbBuilder& b, const CrowdTake& take, Index a, int inverse_bind, int times,
               tinygltf::Animation& anim) {
  const motion::Skeleton& sk = take.rig().skeleton;
  const std::int32_t J = take.joints(), F = take.frames();
  const int first = static_cast<int>(m.nodes.size());
  tinygltf::Skin skin;
  skin.name = "agent" + std::to_string(a);
  skin.inverseBindMatrices = inverse_bind;
  skin.skeleton = first;
  // Every keyed channel of the agent in one buffer view: the root's
  // translations, then each joint's rotations.
  std::vector<float> keys;
  keys.reserve(static_cast<std::size_t>(F) * (3 + 4 * static_cast<std::size_t>(J)));
  for (std::int32_t f = 0; f < F; ++f) {
    const glm::vec3& p = take.root_position(f, a);
    keys.insert(keys.end(), {p.x, p.y, p.z});
  }
  for (std::int32_t j = 0; j < J; ++j)
    for (std::int32_t f = 0; f < F; ++f) {
      const glm::quat& q = take.rotation(f, a, j);
      keys.insert(keys.end(), {q.x, q.y, q.z, q.w});
    }
  const int view = b.view(keys.data(), keys.size() * sizeof(float));
  auto channel = [&](int node, const char* path, std::size_t offset, int type) {
    tinygltf::AnimationSampler s;
    s.input = times;
    s.output = b.accessor(view, offset, TINYGLTF_COMPONENT_TYPE_FLOAT, type, static_cast<std::size_t>(F));
    s.interpolation = "LINEAR";
    anim.samplers.push_back(s);
    tinygltf::AnimationChannel c;
    c.sampler = static_cast<int>(anim.samplers.size()) - 1;
    c.target_node = node;
    c.target_path = path;
    anim.channels.push_back(c);
  };
  for (std::int32_t j = 0; j < J; ++j) {
    tinygltf::Node n;
    n.name = skin.name + "/" + sk.names[static_cast<std::size_t>(j)];
    const glm::quat& q = take.rotation(0, a, j);
    n.rotation = to_doubles(q);
    if (sk.parents[static_cast<std::size_t>(j)] < 0) {
      n.translation = to_doubles(take.root_position(0, a));
      const double s = take.scale(a);
      n.scale = {s, s, s};
      channel(first + j, "translation", 0, TINYGLTF_TYPE_VEC3);
    } else {
      n.translation = to_doubles(sk.offsets[static_cast<std::size_t>(j)]);
    }
    channel(first + j, "rotation", (3 + 4 * static_cast<std::size_t>(j)) * static_cast<std::size_t>(F) * sizeof(float),
            TINYGLTF_TYPE_VEC4);
    for (std::int32_t c = j + 1; c < J; ++c)
      if (sk.parents[static_cast<std::size_t>(c)] == j) n.children.push_back(first + c);
    m.nodes.push_back(n);
    skin.joints.push_back(first + j);
  }
  tinygltf::Node body;
  body.name = skin.name + "/body";
  body.mesh = 0;
  body.skin = static_cast<int>(m.skins.size());
  m.nodes.push_back(body);
  m.skins.push_back(skin);
  for (std::int32_t j = 0; j < J; ++j)
    if (sk.parents[static_cast<std::size_t>(j)] < 0) m.scenes[0].nodes.push_back(first + j);
  m.scenes[0].nodes.push_back(first + J);
}

}  // namespace

CrowdTake::CrowdTake(anim::Rig rig, std::vector<float> scales, double fps)
    : rig_(std::move(rig)), scales_(std::move(scales)), fps_(fps) {
  if (!(fps > 0.0) || !std::isfinite(fps)) throw Error("must be a positive frame rate", at_field("fps"));
}

void CrowdTake::add_frame(Span<const glm::vec3> joint_positions, Span<const glm::quat> joint_rotations) {
  const Index n = agents();
  const std::int32_t J = joints();
  if (joint_positions.size() != n * J || joint_rotations.size() != n * J)
    throw Error("a frame needs agents x joints positions and rotations", at_field("joint_positions"));
  const std::vector<std::int32_t>& parents = rig_.skeleton.parents;
  for (Index a = 0; a < n; ++a) {
    const Index base = a * J;
    for (std::int32_t j = 0; j < J; ++j) {
      const std::int32_t p = parents[static_cast<std::size_t>(j)];
      const glm::quat& world = joint_rotations[base + j];
      if (p < 0) {
        root_positions_.push_back(joint_positions[base + j]);
        rotations_.push_back(glm::normalize(world));
      } else {
        rotations_.push_back(glm::normalize(glm::inverse(joint_rotations[base + p]) * world));
      }
    }
  }
  ++frames_;
}

const glm::vec3& CrowdTake::root_position(std::int32_t frame, Index a) const {
  return root_positions_[static_cast<std::size_t>(frame) * static_cast<std::size_t>(agents()) +
                         static_cast<std::size_t>(a)];
}

const glm::quat& CrowdTake::rotation(std::int32_t frame, Index a, std::int32_t joint) const {
  const std::size_t row =
      static_cast<std::size_t>(frame) * static_cast<std::size_t>(agents()) + static_cast<std::size_t>(a);
  return rotations_[row * static_cast<std::size_t>(joints()) + static_cast<std::size_t>(joint)];
}

double CrowdTake::estimate_bytes(const anim::Rig& rig, Index agents, std::int64_t frames) {
  const double J = rig.joint_count(), n = static_cast<double>(agents), f = static_cast<double>(frames);
  const double keys = n * f * (3.0 + 4.0 * J) * 4.0 + f * 4.0;
  const double mesh = static_cast<double>(rig.mesh.vertex_count()) * (12 + 12 + 8 + 16) +
                      static_cast<double>(rig.mesh.indices.size()) * 4;
  const double json = n * (J + 1.0) * 420.0;  // nodes, accessors, samplers and channels per joint
  return keys + mesh + J * 64.0 + json;
}

void write_crowd_glb(const std::string& path, const CrowdTake& take) {
  tinygltf::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "throng export-crowd";
  m.asset.extras = tinygltf::Value(tinygltf::Value::Object{{"fps", tinygltf::Value(take.fps())}});
  m.scenes.resize(1);
  m.scenes[0].name = "crowd";
  m.defaultScene = 0;
  GlbBuilder b(m);
  add_mesh(m, b, take.rig().mesh);
  const int inverse_bind = add_inverse_bind(b, take.rig());
  std::vector<float> times(static_cast<std::size_t>(take.frames()));
  for (std::size_t f = 0; f < times.size(); ++f) times[f] = static_cast<float>(static_cast<double>(f) / take.fps());
  const int time_accessor = b.accessor(b.view(times.data(), times.size() * sizeof(float)), 0,
                                       TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, times.size(),
                                       {times.empty() ? 0.0 : times.front()}, {times.empty() ? 0.0 : times.back()});
  tinygltf::Animation anim;
  anim.name = "crowd";
  for (Index a = 0; a < take.agents(); ++a) add_agent(m, b, take, a, inverse_bind, time_accessor, anim);
  if (take.frames() > 0) m.animations.push_back(std::move(anim));

  OutputFile file(path);
  {
    std::ofstream out(file.writing_path(), std::ios::binary | std::ios::trunc);
    if (!out) throw Error("cannot open for writing", in_file(path));
    tinygltf::TinyGLTF writer;
    const bool ok = writer.WriteGltfSceneToStream(&m, out, false, true);
    out.flush();
    if (!ok || !out) throw Error(std::string("write failed: ") + std::strerror(errno), in_file(path));
  }
  file.commit();
}

namespace {

// Accessor `index` of `m` as `T` per element (its component type and type
// checked, every element inside its buffer view and buffer), tightly packed.
template <class T>
std::vector<T> read_accessor(const tinygltf::Model& m, int index, int component, int type, const std::string& path,
                             const std::string& what) {
  if (index < 0 || index >= static_cast<int>(m.accessors.size()))
    throw Error(what + ": no such accessor", in_file(path, what));
  const tinygltf::Accessor& a = m.accessors[static_cast<std::size_t>(index)];
  if (a.componentType != component || a.type != type || a.bufferView < 0 ||
      a.bufferView >= static_cast<int>(m.bufferViews.size()))
    throw Error(what + ": unexpected component type or type", in_file(path, what));
  const tinygltf::BufferView& v = m.bufferViews[static_cast<std::size_t>(a.bufferView)];
  if (v.buffer < 0 || v.buffer >= static_cast<int>(m.buffers.size()))
    throw Error(what + ": no such buffer", in_file(path, what));
  const std::vector<unsigned char>& data = m.buffers[static_cast<std::size_t>(v.buffer)].data;
  const std::size_t stride = v.byteStride != 0 ? v.byteStride : sizeof(T);
  const std::size_t start = v.byteOffset + a.byteOffset;
  if (a.count > 0 && (start + (a.count - 1) * stride + sizeof(T) > v.byteOffset + v.byteLength ||
                      v.byteOffset + v.byteLength > data.size()))
    throw Error(what + ": data beyond its buffer", in_file(path, what));
  std::vector<T> out(a.count);
  for (std::size_t i = 0; i < a.count; ++i) std::memcpy(&out[i], &data[start + i * stride], sizeof(T));
  return out;
}

glm::vec3 vec3_of(const std::vector<double>& v, glm::vec3 otherwise) {
  return v.size() == 3 ? glm::vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]))
                       : otherwise;
}

// Images are not part of a crowd: skip them rather than decode them.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

// Rejects a .glb whose BIN chunk runs past the end of `bytes`. tinygltf 2.7
// checks the payload against the file's length without the chunk's 8-byte
// header, then copies buffers from it: up to 8 bytes past the end of the input.
// Other bad layouts (short header, JSON chunk too long) are left to tinygltf.
void check_bin_chunk(std::span<const unsigned char> bytes, const std::string& path) {
  if (bytes.size() < 20) return;
  const auto u32_at = [&](std::uint64_t at) {  // GLB is little-endian, as are the hosts throng builds for
    std::uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, sizeof v);
    return std::uint64_t{v};
  };
  const std::uint64_t length = std::min<std::uint64_t>(u32_at(8), bytes.size());
  const std::uint64_t bin_at = 20 + u32_at(12);
  if (bin_at >= length) return;
  if (bin_at + 8 > length || bin_at + 8 + u32_at(bin_at) > length)
    throw Error("not a glTF binary: its BIN chunk runs past the end of the file", in_file(path));
}

// The glTF model in `bytes` (a .glb under 4 GiB), images skipped; throws
// Error naming `path` when it does not parse.
tinygltf::Model parse_glb(std::span<const unsigned char> bytes, const std::string& path) {
  if (bytes.size() >= (std::size_t{1} << 32)) throw Error("4 GiB or larger", in_file(path));
  check_bin_chunk(bytes, path);
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  std::string err, warn;
  bool loaded = false;
  try {  // tinygltf 2.7 throws std::out_of_range on some malformed JSON chunks
    loaded = loader.LoadBinaryFromMemory(&m, &err, &warn, bytes.data(), static_cast<unsigned int>(bytes.size()));
  } catch (const std::exception& e) {
    err = e.what();
  }
  if (!loaded) throw Error("not a glTF binary: " + err, in_file(path));
  return m;
}

// Parent node index of every node (-1: none), from the nodes' children.
std::vector<int> parent_nodes(const tinygltf::Model& m, const std::string& path) {
  std::vector<int> parent_node(m.nodes.size(), -1);
  for (std::size_t i = 0; i < m.nodes.size(); ++i)
    for (const int c : m.nodes[i].children) {
      if (c < 0 || c >= static_cast<int>(m.nodes.size())) throw Error("child out of range", in_file(path, "nodes"));
      parent_node[static_cast<std::size_t>(c)] = static_cast<int>(i);
    }
  return parent_node;
}

// Skin 0's inverse bind matrices as rows (glTF stores them column-major),
// one per joint.
std::vector<anim::Mat3x4> read_inverse_bind(const tinygltf::Model& m, std::int32_t joints, const std::string& path) {
  std::vector<anim::Mat3x4> inverse_bind;
  for (const glm::mat4& ibm : read_accessor<glm::mat4>(m, m.skins[0].inverseBindMatrices, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                                       TINYGLTF_TYPE_MAT4, path, "inverseBindMatrices")) {
    const float* c = &ibm[0][0];  // column-major
    anim::Mat3x4 x;
    x.r0 = glm::vec4(c[0], c[4], c[8], c[12]);
    x.r1 = glm::vec4(c[1], c[5], c[9], c[13]);
    x.r2 = glm::vec4(c[2], c[6], c[10], c[14]);
    inverse_bind.push_back(x);
  }
  if (static_cast<std::int32_t>(inverse_bind.size()) != joints)
    throw Error("one inverse bind matrix per joint expected", in_file(path, "skins[0]"));
  return inverse_bind;
}

// Mesh 0's first primitive as a skinned mesh of `joints` joints, validated.
anim::SkinnedMesh read_mesh(const tinygltf::Model& m, std::int32_t joints, const std::string& path) {
  if (m.meshes[0].primitives.empty()) throw Error("the mesh has no primitive", in_file(path, "meshes[0]"));
  const tinygltf::Primitive& prim = m.meshes[0].primitives[0];
  auto attribute = [&](const char* name) {
    const auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) throw Error(std::string("mesh has no ") + name, in_file(path, "meshes[0]"));
    return it->second;
  };
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  anim::SkinnedMesh mesh;
  mesh.joint_count = joints;
  mesh.positions = read_accessor<glm::vec3>(m, attribute("POSITION"), kFloat, TINYGLTF_TYPE_VEC3, path, "POSITION");
  mesh.normals = read_accessor<glm::vec3>(m, attribute("NORMAL"), kFloat, TINYGLTF_TYPE_VEC3, path, "NORMAL");
  mesh.weights = read_accessor<glm::vec4>(m, attribute("WEIGHTS_0"), kFloat, TINYGLTF_TYPE_VEC4, path, "WEIGHTS_0");
  mesh.joints = read_accessor<glm::u16vec4>(m, attribute("JOINTS_0"), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                            TINYGLTF_TYPE_VEC4, path, "JOINTS_0");
  mesh.indices = read_accessor<std::uint32_t>(m, prim.indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                              TINYGLTF_TYPE_SCALAR, path, "indices");
  try {
    mesh.validate();
  } catch (const Error& e) {
    throw Error(std::string("mesh: ") + e.what(), in_file(path, "meshes[0]"));
  }
  return mesh;
}

// The joint a channel of animation `anim` keys, as its index a * joints + j,
// after checking the channel's sampler, target node (not a mesh node) and
// path (translation or rotation).
std::size_t keyed_joint(const tinygltf::Model& m, const tinygltf::Animation& anim, const tinygltf::AnimationChannel& c,
                        std::int32_t joints, const std::string& path) {
  if (c.sampler < 0 || c.sampler >= static_cast<int>(anim.samplers.size()) || c.target_node < 0 ||
      c.target_node >= static_cast<int>(m.nodes.size()))
    throw Error("channel out of range", in_file(path, "animations[0].channels"));
  const int node = c.target_node;
  if (node % (joints + 1) == joints) throw Error("a mesh node is animated", in_file(path, "animations[0].channels"));
  if (c.target_path != "rotation" && c.target_path != "translation")
    throw Error("only translation and rotation are keyed", in_file(path, c.target_path));
  return static_cast<std::size_t>((node / (joints + 1)) * joints + node % (joints + 1));
}
}  // namespace

CrowdGlb::CrowdGlb(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error("no such .glb file", in_file(path));
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size >= (std::uintmax_t{1} << 32)) throw Error("unreadable, or 4 GiB or larger", in_file(path));
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())))
    throw Error("cannot read", in_file(path));
  load(bytes, path);
}

CrowdGlb CrowdGlb::parse(std::span<const unsigned char> bytes, const std::string& name) {
  CrowdGlb glb;
  glb.load(bytes, name);
  return glb;
}

// Stages: parse, layout checks, joint nodes (parents, rest pose), inverse
// bind matrices, mesh, then the keyed channels of animation 0.
void CrowdGlb::load(std::span<const unsigned char> bytes, const std::string& path) {
  const tinygltf::Model m = parse_glb(bytes, path);
  if (m.skins.empty() || m.meshes.size() != 1)
    throw Error("expected one mesh and a skin per agent (throng export-crowd's layout)", in_file(path));
  agents_ = static_cast<Index>(m.skins.size());
  joints_ = static_cast<std::int32_t>(m.skins[0].joints.size());
  if (joints_ == 0 || m.nodes.size() != static_cast<std::size_t>(agents_) * static_cast<std::size_t>(joints_ + 1))
    throw Error("node count is not agents x (joints + 1)", in_file(path, "nodes"));
  if (m.asset.extras.Has("fps")) fps_ = m.asset.extras.Get("fps").GetNumberAsDouble();

  const std::vector<int> parent_node = parent_nodes(m, path);
  nodes_.resize(static_cast<std::size_t>(agents_) * static_cast<std::size_t>(joints_));
  for (Index a = 0; a < agents_; ++a) {
    const tinygltf::Skin& skin = m.skins[static_cast<std::size_t>(a)];
    const int first = static_cast<int>(a) * (joints_ + 1);
    if (static_cast<std::int32_t>(skin.joints.size()) != joints_)
      throw Error("skins differ in joint count", in_file(path, "skins"));
    for (std::int32_t j = 0; j < joints_; ++j) {
      if (skin.joints[static_cast<std::size_t>(j)] != first + j)
        throw Error("skin joints out of layout", in_file(path, "skins"));
      const tinygltf::Node& gn = m.nodes[static_cast<std::size_t>(first + j)];
      Node& n = nodes_[static_cast<std::size_t>(a * joints_ + j)];
      const int p = parent_node[static_cast<std::size_t>(first + j)];
      n.parent = p < 0 ? -1 : p - first;
      if (n.parent >= j) throw Error("a joint's parent comes after it", in_file(path, "nodes"));
      n.translation = vec3_of(gn.translation, glm::vec3(0.0f));
      if (gn.rotation.size() == 4)
        n.rotation = glm::quat(static_cast<float>(gn.rotation[3]), static_cast<float>(gn.rotation[0]),
                               static_cast<float>(gn.rotation[1]), static_cast<float>(gn.rotation[2]));
      n.scale = gn.scale.size() == 3 ? static_cast<float>(gn.scale[0]) : 1.0f;
    }
  }
  inverse_bind_ = read_inverse_bind(m, joints_, path);
  mesh_ = read_mesh(m, joints_, path);

  if (m.animations.empty()) return;
  const tinygltf::Animation& anim = m.animations[0];
  constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
  for (const tinygltf::AnimationChannel& c : anim.channels) {
    Node& n = nodes_[keyed_joint(m, anim, c, joints_, path)];
    const tinygltf::AnimationSampler& s = anim.samplers[static_cast<std::size_t>(c.sampler)];
    std::size_t frames = 0;
    if (c.target_path == "rotation") {
      rotation_keys_.push_back(
          read_accessor<glm::vec4>(m, s.output, kFloat, TINYGLTF_TYPE_VEC4, path, "sampler output"));
      frames = rotation_keys_.back().size();
      n.rotation_keys = static_cast<std::int32_t>(rotation_keys_.size()) - 1;
    } else {
      translation_keys_.push_back(
          read_accessor<glm::vec3>(m, s.output, kFloat, TINYGLTF_TYPE_VEC3, path, "sampler output"));
      frames = translation_keys_.back().size();
      n.translation_keys = static_cast<std::int32_t>(translation_keys_.size()) - 1;
    }
    if (frames == 0) throw Error("a channel without keys", in_file(path, "animations[0]"));
    if (frames_ != 0 && static_cast<std::int32_t>(frames) != frames_)
      throw Error("channels differ in key count", in_file(path, "animations[0]"));
    frames_ = static_cast<std::int32_t>(frames);
  }
}

void CrowdGlb::joint_frames(Index a, std::int32_t frame, std::vector<glm::vec3>& positions,
                            std::vector<glm::quat>& rotations, std::vector<float>& scales) const {
  if (a < 0 || a >= agents_ || frame < 0 || (frames_ > 0 && frame >= frames_))
    throw Error("agent or frame out of range", at_field("frame"));
  positions.resize(static_cast<std::size_t>(joints_));
  rotations.resize(static_cast<std::size_t>(joints_));
  scales.resize(static_cast<std::size_t>(joints_));
  const auto k = static_cast<std::size_t>(frame);
  for (std::int32_t j = 0; j < joints_; ++j) {
    const Node& n = nodes_[static_cast<std::size_t>(a * joints_ + j)];
    glm::vec3 t = n.translation;
    glm::quat r = n.rotation;
    if (n.translation_keys >= 0) t = translation_keys_[static_cast<std::size_t>(n.translation_keys)][k];
    if (n.rotation_keys >= 0) {
      const glm::vec4& v = rotation_keys_[static_cast<std::size_t>(n.rotation_keys)][k];  // x, y, z, w
      r = glm::quat(v.w, v.x, v.y, v.z);
    }
    const auto J = static_cast<std::size_t>(j);
    if (n.parent < 0) {
      positions[J] = t;
      rotations[J] = r;
      scales[J] = n.scale;
    } else {
      const auto P = static_cast<std::size_t>(n.parent);
      positions[J] = positions[P] + rotations[P] * (scales[P] * t);
      rotations[J] = rotations[P] * r;
      scales[J] = scales[P] * n.scale;
    }
  }
}

}  // namespace throng::io
