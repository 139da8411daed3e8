#include "core/error.h"

#include "core/check.h"

namespace throng {

std::string Location::to_string() const {
  // Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+.
  std::string s = file;
  if (line > 0) {
    s.append(s.empty() ? "line " : ":").append(std::to_string(line));
    if (column > 0) s.append(":").append(std::to_string(column));
  }
  if (!field.empty()) s.append(s.empty() ? "" : ": ").append(field);
  return s;
}

static std::string compose(const std::string& message, const Location& where) {
  return where.empty() ? message : where.to_string() + ": " + message;
}

Error::Error(std::string message, Location where)
    : std::runtime_error(compose(message, where)), message_(std::move(message)), where_(std::move(where)) {}

Location at_line(std::string file, int line, int column) {
  Location l;
  l.file = std::move(file);
  l.line = line;
  l.column = column;
  return l;
}

Location at_field(std::string field, std::string file) {
  Location l;
  l.file = std::move(file);
  l.field = std::move(field);
  return l;
}

void check_length(const char* owner, const char* field, std::int64_t got, std::int64_t want) {
  if (got != want)
    throw Error("has " + std::to_string(got) + " elements, expected " + std::to_string(want),
                at_field(std::string(owner) + "." + field));
}

void check_optional_length(const char* owner, const char* field, std::int64_t got, std::int64_t want) {
  if (got != 0) check_length(owner, field, got, want);
}

}  // namespace throng
