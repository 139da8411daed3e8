// The malformed corpus (tests/data/bvh_bad, made by make_corpus.py): every
// file gives an Error at the expected line with the expected text, no crash.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/error.h"
#include "io/bvh_reader.h"

namespace throng::io {
namespace {

const std::filesystem::path kCorpus = std::filesystem::path(THRONG_SOURCE_DIR) / "tests" / "data" / "bvh_bad";

struct Expectation {
  std::string file;
  int line = 0;
  std::string text;
};

std::vector<Expectation> expectations() {
  std::vector<Expectation> out;
  std::ifstream in(kCorpus / "EXPECTED.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto a = line.find('\t'), b = line.find('\t', a + 1);
    out.push_back({line.substr(0, a), std::stoi(line.substr(a + 1, b - a - 1)), line.substr(b + 1)});
  }
  return out;
}

TEST(BvhBadCorpus, EveryFileGivesAClearErrorAtItsLine) {
  const auto cases = expectations();
  ASSERT_GE(cases.size(), 40u) << "corpus missing at " << kCorpus;
  for (const auto& c : cases) {
    const std::string path = (kCorpus / c.file).string();
    try {
      read_bvh(path);
      ADD_FAILURE() << c.file << ": read without error";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.location().file, path);
      EXPECT_EQ(e.location().line, c.line) << what;
      EXPECT_NE(what.find(path + ":" + std::to_string(c.line)), std::string::npos) << what;
      EXPECT_NE(what.find(c.text), std::string::npos) << c.file << "\n  got:    " << what << "\n  wanted: " << c.text;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
    }
  }
}

TEST(BvhBadCorpus, EveryFileIsListed) {
  std::set<std::string> listed;
  for (const auto& c : expectations()) listed.insert(c.file);
  for (const auto& entry : std::filesystem::directory_iterator(kCorpus))
    if (entry.path().extension() == ".bvh") {
      EXPECT_TRUE(listed.count(entry.path().filename().string())) << entry.path();
    }
}

// Every prefix of a valid file is either valid or a clean Error (what a
// truncated download looks like), and so is every single-byte change.
TEST(BvhBadCorpus, TruncationsAndByteFlipsNeverCrash) {
  std::ifstream in(kCorpus / "wrong_row_count.bvh", std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  text.replace(text.find(" 2.500000"), 9, " 2.500000 3.500000");  // the valid original
  ASSERT_NO_THROW(parse_bvh(text, "valid.bvh"));
  int errors = 0;
  for (std::size_t n = 0; n < text.size(); ++n) {
    try {
      parse_bvh(std::string_view(text).substr(0, n), "prefix.bvh");
    } catch (const Error& e) {
      ++errors;
      EXPECT_GT(e.location().line, 0) << e.what();
    }
  }
  EXPECT_GT(errors, static_cast<int>(text.size()) / 2);
  for (std::size_t i = 0; i < text.size(); i += 3)
    for (char c : {'\0', '\n', '{', '}', '-', 'e', '9', ' '}) {
      std::string t = text;
      t[i] = c;
      try {
        parse_bvh(t, "flip.bvh");
      } catch (const Error& e) {
        EXPECT_GT(e.location().line, 0) << e.what();
      }
    }
}

}  // namespace
}  // namespace throng::io
