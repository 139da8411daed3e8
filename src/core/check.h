// Length checks of a job's or an API's spans: one message and one field path
// ("Owner.field") for every "this span has the wrong size" error.
#pragma once

#include <cstdint>

namespace throng {

// Throws Error("has <got> elements, expected <want>") at field "<owner>.<field>" unless got == want.
void check_length(const char* owner, const char* field, std::int64_t got, std::int64_t want);
// The same for an optional span: an empty one passes.
void check_optional_length(const char* owner, const char* field, std::int64_t got, std::int64_t want);

}  // namespace throng
