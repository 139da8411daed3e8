// BVH reader: every channel layout against an independent matrix-based FK,
// whitespace and line-end variants, units, and the errors it must give.
#include "io/bvh_reader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "motion/fk.h"

namespace throng::io {
namespace {

// Every layout: 6 channels interleaved, CHANNELS 0, no CHANNELS line, one and
// two rotations, positions only, 6 channels on a non-root joint, a partial
// position channel, End Sites, scientific notation, '+', tabs and spaces.
const char* kHierarchy =
    "HIERARCHY\n"
    "ROOT Pelvis\n"
    "{\n"
    "\tOFFSET 1 2 3\n"
    "\tCHANNELS 6 Zrotation Xposition Yrotation Yposition Xrotation Zposition\n"
    "\tJOINT NoChannels\n"
    "\t{\n"
    "\t\tOFFSET 0 10 0\n"
    "\t\tCHANNELS 0\n"
    "\t\tJOINT OneRot\n"
    "\t\t{\n"
    "\t\t\tOFFSET 0 5 1e1\n"
    "\t\t\tCHANNELS 1 Xrotation\n"
    "\t\t\tEnd Site\n"
    "\t\t\t{\n"
    "\t\t\t\tOFFSET 0 3 0\n"
    "\t\t\t}\n"
    "\t\t}\n"
    "\t}\n"
    "  JOINT NoChannelsLine   \n"
    "  {\n"
    "    OFFSET -5 0 0\n"
    "    JOINT TwoRot\n"
    "    {\n"
    "      OFFSET -4 0 +2.5\n"
    "      CHANNELS 2 Yrotation Zrotation\n"
    "      JOINT PosOnly\n"
    "      {\n"
    "        OFFSET 0 -7 0\n"
    "        CHANNELS 3 Zposition Xposition Yposition\n"
    "        JOINT SixChan\n"
    "        {\n"
    "          OFFSET 0 -6.0E0 0\n"
    "          CHANNELS 6 Xrotation Yposition Zrotation Xposition Yrotation Zposition\n"
    "          End Site\n"
    "          {\n"
    "            OFFSET 0 0 4\n"
    "          }\n"
    "        }\n"
    "      }\n"
    "      JOINT PartialPos\n"
    "      {\n"
    "        OFFSET 1 1 1\n"
    "        CHANNELS 4 Yposition Zrotation Yrotation Xrotation\n"
    "      }\n"
    "    }\n"
    "  }\n"
    "}\n";

struct RefJoint {
  const char* name;
  int parent;
  glm::dvec3 offset;
  std::string channels;  // one letter pair per channel: "Zr Xp ..."
};
const std::vector<RefJoint> kJoints = {{"Pelvis", -1, {1, 2, 3}, "Zr Xp Yr Yp Xr Zp"},
                                       {"NoChannels", 0, {0, 10, 0}, ""},
                                       {"OneRot", 1, {0, 5, 10}, "Xr"},
                                       {"NoChannelsLine", 0, {-5, 0, 0}, ""},
                                       {"TwoRot", 3, {-4, 0, 2.5}, "Yr Zr"},
                                       {"PosOnly", 4, {0, -7, 0}, "Zp Xp Yp"},
                                       {"SixChan", 5, {0, -6, 0}, "Xr Yp Zr Xp Yr Zp"},
                                       {"PartialPos", 4, {1, 1, 1}, "Yp Zr Yr Xr"}};
constexpr int kChannels = 22;

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < s.size()) {
    const std::size_t j = s.find(' ', i);
    out.push_back(s.substr(i, j == std::string::npos ? std::string::npos : j - i));
    if (j == std::string::npos) break;
    i = j + 1;
  }
  return out;
}

// Reference model-space positions from 4x4 matrices: T(translation) then
// the rotations multiplied in listed order.
std::vector<glm::dvec3> reference_positions(const std::vector<double>& row, double scale) {
  std::vector<glm::dmat4> global(kJoints.size());
  std::vector<glm::dvec3> out(kJoints.size());
  std::size_t v = 0;
  for (std::size_t j = 0; j < kJoints.size(); ++j) {
    glm::dvec3 t = kJoints[j].offset;
    glm::dmat4 r(1.0);
    for (const std::string& c : kJoints[j].channels.empty() ? std::vector<std::string>{} : split(kJoints[j].channels)) {
      const int axis = c[0] - 'X';
      const double value = row[v++];
      if (c[1] == 'p') {
        t[axis] = value;
      } else {
        r = r * glm::rotate(glm::dmat4(1.0), glm::radians(value), glm::dvec3(axis == 0, axis == 1, axis == 2));
      }
    }
    const glm::dmat4 local = glm::translate(glm::dmat4(1.0), t * scale) * r;
    global[j] = kJoints[j].parent < 0 ? local : global[static_cast<std::size_t>(kJoints[j].parent)] * local;
    out[j] = glm::dvec3(global[j][3]);
  }
  return out;
}

struct Motion {
  std::string text;
  std::vector<std::vector<double>> rows;
};

// Random rows written in assorted number formats, with blank lines between.
Motion make_motion(int frames, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-180.0, 180.0), pos(-50.0, 50.0);
  Motion m;
  m.text = std::string(kHierarchy) + "MOTION\nFrames:\t" + std::to_string(frames) + "\nFrame Time:0.04  \n";
  int k = 0;
  for (int f = 0; f < frames; ++f) {
    std::vector<double> row;
    std::string line;
    for (const auto& j : kJoints) {
      if (j.channels.empty()) continue;
      for (const std::string& c : split(j.channels)) {
        const double v = c[1] == 'p' ? pos(rng) : angle(rng);
        char buf[64];
        const char* formats[] = {"%.9g", "%.6e", "%+.7f", "%.8E"};
        std::snprintf(buf, sizeof buf, formats[k++ % 4], v);
        row.push_back(std::strtod(buf, nullptr));
        line += (line.empty() ? "" : (k % 3 == 0 ? "\t" : " "));
        line += buf;
      }
    }
    m.rows.push_back(row);
    m.text += line + (f % 2 == 0 ? "  \n\n" : "\n");
  }
  return m;
}

BvhReadOptions in_cm() {
  BvhReadOptions o;
  o.unit = motion::LengthUnit::Centimetre;
  return o;
}

TEST(BvhReader, EveryChannelLayoutMatchesMatrixReference) {
  const Motion m = make_motion(25, 1);
  const BvhFile b = parse_bvh(m.text, "layouts.bvh", in_cm());
  ASSERT_EQ(b.skeleton.joint_count(), static_cast<std::int32_t>(kJoints.size()));
  EXPECT_EQ(b.channel_count(), kChannels);
  EXPECT_EQ(b.clip.frame_count, 25);
  EXPECT_EQ(b.frame_time, 0.04);
  EXPECT_FLOAT_EQ(b.clip.frame_time, 0.04f);
  EXPECT_EQ(b.end_site_count, 2);
  EXPECT_FALSE(b.unit_detected);
  EXPECT_EQ(b.channel_list(0), "Zrotation Xposition Yrotation Yposition Xrotation Zposition");
  EXPECT_EQ(b.rotation_order(0), "ZYX");
  EXPECT_EQ(b.rotation_order(1), "");
  EXPECT_EQ(b.rotation_order(4), "YZ");
  EXPECT_EQ(b.rotation_order(6), "XZY");
  EXPECT_FALSE(b.clip.translations.empty());  // non-root joints have position channels
  for (std::size_t j = 0; j < kJoints.size(); ++j) {
    EXPECT_EQ(b.skeleton.names[j], kJoints[j].name);
    EXPECT_EQ(b.skeleton.parents[j], kJoints[j].parent);
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(b.skeleton.offsets[j][i], kJoints[j].offset[i] * 0.01, 1e-7);
  }
  EXPECT_TRUE(b.skeleton.has_end_site[2]);
  EXPECT_NEAR(b.skeleton.end_sites[6].z, 0.04f, 1e-7);
  const motion::ModelSpaceClip ms = motion::forward_kinematics(b.skeleton, b.clip);
  double worst = 0;
  for (int f = 0; f < 25; ++f) {
    const auto ref = reference_positions(m.rows[static_cast<std::size_t>(f)], 0.01);
    for (std::size_t j = 0; j < kJoints.size(); ++j)
      worst = std::max(worst, glm::length(glm::dvec3(ms.position(f, static_cast<std::int32_t>(j))) - ref[j]));
  }
  EXPECT_LT(worst, 2e-6) << "metres";
}

TEST(BvhReader, LineEndingsDoNotMatter) {
  const Motion m = make_motion(6, 2);
  const BvhFile lf = parse_bvh(m.text, "lf.bvh", in_cm());
  std::string crlf, cr, mixed;
  int n = 0;
  for (char c : m.text) {
    if (c == '\n') {
      crlf += "\r\n";
      cr += "\r";
      mixed += (n++ % 3 == 0) ? "\r\n" : (n % 3 == 1 ? "\n" : "\r");
    } else {
      crlf += c;
      cr += c;
      mixed += c;
    }
  }
  for (const std::string* text : {&crlf, &cr, &mixed}) {
    const BvhFile b = parse_bvh(*text, "variant.bvh", in_cm());
    ASSERT_EQ(b.clip.rotations.size(), lf.clip.rotations.size());
    for (std::size_t i = 0; i < lf.clip.rotations.size(); ++i) ASSERT_EQ(b.clip.rotations[i], lf.clip.rotations[i]);
    EXPECT_EQ(b.clip.root_positions, lf.clip.root_positions);
    EXPECT_EQ(b.clip.translations, lf.clip.translations);
  }
}

TEST(BvhReader, UnitsOptionScalesEverything) {
  const Motion m = make_motion(3, 3);
  const BvhFile cm = parse_bvh(m.text, "u.bvh", in_cm());
  BvhReadOptions o;
  o.unit = motion::LengthUnit::Inch;
  const BvhFile in = parse_bvh(m.text, "u.bvh", o);
  EXPECT_EQ(in.unit, motion::LengthUnit::Inch);
  for (std::size_t j = 0; j < kJoints.size(); ++j)
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(in.skeleton.offsets[j][i], cm.skeleton.offsets[j][i] * 2.54f, 1e-6);
  for (int f = 0; f < 3; ++f)
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(in.clip.root_positions[static_cast<std::size_t>(f)][i],
                  cm.clip.root_positions[static_cast<std::size_t>(f)][i] * 2.54f, 1e-5);
}

// A small human in a given unit: legs 0.85 m, so detection has a real answer.
std::string human(double units_per_metre) {
  auto v = [&](double metres) { return std::to_string(metres * units_per_metre); };
  return "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
         "Yrotation\n"
         "JOINT LeftUpLeg\n{\nOFFSET " +
         v(0.1) +
         " 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
         "JOINT LeftLeg\n{\nOFFSET 0 -" +
         v(0.43) +
         " 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
         "JOINT LeftFoot\n{\nOFFSET 0 -" +
         v(0.42) +
         " 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
         "End Site\n{\nOFFSET 0 0 " +
         v(0.15) +
         "\n}\n}\n}\n}\n"
         "JOINT Spine\n{\nOFFSET 0 " +
         v(0.1) +
         " 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n"
         "End Site\n{\nOFFSET 0 " +
         v(0.5) +
         " 0\n}\n}\n}\n"
         "MOTION\nFrames: 1\nFrame Time: 0.0333333\n0 " +
         v(0.95) + " 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";
}

TEST(BvhReader, DetectsUnitsFromLegLength) {
  const std::pair<double, motion::LengthUnit> cases[] = {{1.0, motion::LengthUnit::Metre},
                                                         {100.0, motion::LengthUnit::Centimetre},
                                                         {1000.0, motion::LengthUnit::Millimetre},
                                                         {1.0 / 0.0254, motion::LengthUnit::Inch},
                                                         {0.45 / 0.0254, motion::LengthUnit::CmuAsf}};
  for (const auto& [per_metre, unit] : cases) {
    const BvhFile b = parse_bvh(human(per_metre), "human.bvh");
    EXPECT_TRUE(b.unit_detected);
    EXPECT_EQ(b.unit, unit) << per_metre;
    EXPECT_NEAR(b.clip.root_positions[0].y, 0.95, 1e-5) << per_metre;
    EXPECT_NEAR(b.skeleton.offsets[2].y, -0.43, 1e-6) << per_metre;
  }
}

TEST(BvhReader, ZeroFramesAndSkeletonOnly) {
  const std::string text = std::string(kHierarchy) + "MOTION\nFrames: 0\nFrame Time: 0.01\n";
  const BvhFile b = parse_bvh(text, "empty.bvh", in_cm());
  EXPECT_EQ(b.clip.frame_count, 0);
  EXPECT_TRUE(b.clip.rotations.empty());
}

// Parses `text` and checks the Error's line and that its text contains `needle`.
void expect_error(const std::string& text, int line, const std::string& needle,
                  const BvhReadOptions& options = in_cm()) {
  try {
    parse_bvh(text, "bad.bvh", options);
    ADD_FAILURE() << "no error; expected line " << line << ": " << needle;
  } catch (const Error& e) {
    EXPECT_EQ(e.location().file, "bad.bvh");
    EXPECT_EQ(e.location().line, line) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << "got: " << e.what() << "\nwanted: " << needle;
    EXPECT_NE(std::string(e.what()).find("bad.bvh:" + std::to_string(line)), std::string::npos) << e.what();
  }
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

const char* kSmall =
    "HIERARCHY\n"                                                                 // 1
    "ROOT Hips\n"                                                                 // 2
    "{\n"                                                                         // 3
    "  OFFSET 0 0 0\n"                                                            // 4
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"  // 5
    "  JOINT Leg\n"                                                               // 6
    "  {\n"                                                                       // 7
    "    OFFSET 0 -40 0\n"                                                        // 8
    "    CHANNELS 3 Zrotation Xrotation Yrotation\n"                              // 9
    "    End Site\n"                                                              // 10
    "    {\n"                                                                     // 11
    "      OFFSET 0 -40 0\n"                                                      // 12
    "    }\n"                                                                     // 13
    "  }\n"                                                                       // 14
    "}\n"                                                                         // 15
    "MOTION\n"                                                                    // 16
    "Frames: 2\n"                                                                 // 17
    "Frame Time: 0.0333333\n"                                                     // 18
    "1 90 2 0 0 0 10 20 30\n"                                                     // 19
    "1 91 2 0 0 0 11 21 31\n";                                                    // 20

TEST(BvhReader, SmallFileParses) {
  const BvhFile b = parse_bvh(kSmall, "small.bvh", in_cm());
  EXPECT_EQ(b.clip.frame_count, 2);
  EXPECT_NEAR(b.clip.root_positions[1].y, 0.91f, 1e-6);
}

TEST(BvhReader, ErrorsNameLineAndWhatWasExpected) {
  const std::string s = kSmall;
  expect_error(replace(s, "    OFFSET 0 -40 0", "    OFSET 0 -40 0"), 8, "expected 'OFFSET', found 'OFSET'");
  expect_error(replace(s, "HIERARCHY", "HIERARCHX"), 1, "expected 'HIERARCHY', found 'HIERARCHX'");
  expect_error(replace(s, "ROOT Hips", "ROOT"), 2, "expected a joint name");
  expect_error(replace(s, "1 91 2 0 0 0 11 21 31", "1 91 2 0 0 0 11 21"), 20, "frame row 2 has 8 values, expected 9");
  expect_error(replace(s, "1 91 2 0 0 0 11 21 31", "1 91 2 0 0 0 11 21 31 4"), 20,
               "frame row 2 has 10 values, expected 9");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 1O"), 19,
               "expected a number (frame row 1 value 7), found '1O'");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 nan"), 19, "not a finite number: 'nan'");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 -inf"), 19, "not a finite number");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 1e999"), 19, "out of range");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 1,5"), 19, "found '1,5'");
  expect_error(replace(s, "1 90 2 0 0 0 10", "1 90 2 0 0 0 -2e9"), 19, "out of range (magnitude above 1e9): '-2e9'");
  expect_error(replace(s, "    OFFSET 0 -40 0", "    OFFSET 0 1e300 0"), 8, "OFFSET y is out of range");
  expect_error(replace(replace(s, "Frames: 2", "Frames: 3"), "11 21 31", "11.00000000 21.00000000 31.00000000"), 21,
               "file ends after 2 frame rows; 'Frames:' says 3");
  expect_error(replace(s, "Frames: 2", "Frames: 1"), 20, "more frame rows than 'Frames: 1'");
  expect_error(replace(s, "Frames: 2", "Frames: -1"), 17, "must not be negative");
  expect_error(replace(s, "Frames: 2", "Frames: 2.5"), 17, "expected an integer (frame count), found '2.5'");
  expect_error(replace(s, "Frames: 2", "Frames: 99999999999999999999"), 17, "out of range");
  expect_error(replace(s, "Frames: 2", "Frames: 2000000"), 17, "exceeds the limit of 1000000");
  expect_error(replace(s, "Frames: 2", "Frames: 900000"), 17, "bytes follow (truncated file?)");
  expect_error(replace(s, "Frame Time: 0.0333333", "Frame Time: 0"), 18, "frame time must be positive");
  expect_error(replace(s, "Frame Time: 0.0333333", "Frame Time: 0.03 x"), 18,
               "expected the end of the 'Frame Time' line, found 'x'");
  expect_error(replace(s, "Frame Time", "FrameTime"), 18, "expected 'Frame', found 'FrameTime:'");
  expect_error(replace(s, "CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Xrotation Wrotation"), 9,
               "expected a channel name (Xposition ... Zrotation), found 'Wrotation'");
  expect_error(replace(s, "CHANNELS 3 Zrotation Xrotation Yrotation", "CHANNELS 3 Zrotation Xrotation Zrotation"), 9,
               "channel 'Zrotation' listed twice");
  expect_error(replace(s, "CHANNELS 3 Zrotation", "CHANNELS 7 Zrotation"), 9, "channel count must be 0 to 6");
  expect_error(replace(s, "    End Site", "    End Zone"), 10, "expected 'Site' after 'End', found 'Zone'");
  expect_error(replace(s, "  }\n}\nMOTION", "  }\nMOTION"), 15,
               "expected 'JOINT', 'End Site' or '}' in joint 'Hips' opened at line 2, found 'MOTION'");
  expect_error(replace(s, "MOTION", "MOTON"), 16, "expected 'MOTION', found 'MOTON'");
  expect_error(replace(s, "MOTION", "ROOT Again"), 16, "a second ROOT hierarchy is not supported");
  expect_error(replace(s, "    OFFSET 0 -40 0", "    OFFSET 0 -40"), 9,
               "expected a number (OFFSET z), found 'CHANNELS'");
  expect_error(replace(s, "    OFFSET 0 -40 0", "    OFFSET 0 -40 inf"), 8, "OFFSET z is not a finite number");
  expect_error(s.substr(0, s.find("  }\n}\nMOTION")), 14, "file ends inside joint 'Leg' opened at line 6");
  expect_error(s.substr(0, s.find("Frame Time")), 18, "expected 'Frame', found end of file");
  expect_error(std::string(kSmall).substr(0, 0), 1, "expected 'HIERARCHY', found end of file");
  expect_error(replace(s, "Hips", std::string(300, 'a')), 2, "longer than 256 characters");
  expect_error(std::string("HIERARCHY\nROOT \x01\x02\xff\n{\n\x80\x81 0 0 0\n"), 4,
               "expected 'OFFSET', found '\\x80\\x81'");
}

TEST(BvhReader, ResourceLimitsAreCheckedBeforeAllocating) {
  BvhReadOptions o = in_cm();
  o.limits.max_joints = 1;
  expect_error(kSmall, 6, "more than 1 joints (limit)", o);
  o = in_cm();
  o.limits.max_values = 17;
  expect_error(kSmall, 17, "2 frames x 9 channels exceeds the limit of 17 values", o);
  o = in_cm();
  o.limits.max_poses = 3;
  expect_error(kSmall, 17, "2 frames x 2 joints exceeds the limit of 3 joint poses", o);
  o = in_cm();
  o.limits.max_frames = 1;
  expect_error(kSmall, 17, "exceeds the limit of 1", o);
  o = in_cm();
  o.limits.max_file_bytes = 100;
  try {
    parse_bvh(kSmall, "big.bvh", o);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds the limit of 100 bytes"), std::string::npos) << e.what();
  }
  // A hostile frame count with no rows behind it: refused by size, quickly.
  expect_error(replace(kSmall, "Frames: 2", "Frames: 999999"), 17, "truncated file?");
}

TEST(BvhReader, ReadsFromDiskAndReportsMissingFiles) {
  const auto path = std::filesystem::temp_directory_path() / "throng_bvh_reader_test.bvh";
  {
    std::ofstream f(path, std::ios::binary);
    f << kSmall;
  }
  const BvhFile b = read_bvh(path.string(), in_cm());
  EXPECT_EQ(b.name, path.string());
  EXPECT_EQ(b.bytes, std::string(kSmall).size());
  std::filesystem::remove(path);
  try {
    read_bvh("/nonexistent/dir/missing.bvh");
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.location().file, "/nonexistent/dir/missing.bvh");
    EXPECT_NE(std::string(e.what()).find("cannot read"), std::string::npos) << e.what();
  }
}

TEST(BvhReader, TolerantHeaderForms) {
  // Keywords in other cases, the brace on the name line, "Frames:N".
  std::string s = kSmall;
  s = replace(s, "ROOT Hips\n{", "root Hips {");
  s = replace(s, "Frames: 2", "FRAMES:2");
  s = replace(s, "Frame Time: 0.0333333", "frame time:\t\t0.0333333   ");
  s = replace(s, "End Site\n    {", "End Site {");
  s = "\xEF\xBB\xBF" + s;  // byte order mark
  const BvhFile b = parse_bvh(s, "tolerant.bvh", in_cm());
  EXPECT_EQ(b.skeleton.names[0], "Hips");
  EXPECT_EQ(b.clip.frame_count, 2);
  EXPECT_TRUE(b.skeleton.has_end_site[1]);
}

}  // namespace
}  // namespace throng::io
