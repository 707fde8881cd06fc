#ifndef TILTCAL_TESTS_TESTING_JSON_VALUE_H_
#define TILTCAL_TESTS_TESTING_JSON_VALUE_H_

// A small JSON reader for tests (RFC 8259): objects keep their keys in file
// order, numbers keep their text. Strings are UTF-8 with the escapes
// decoded (\uXXXX, surrogate pairs included).

#include <string>
#include <utility>
#include <vector>

namespace tiltcal::testing {

struct JsonValue {
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };
  Kind kind = Kind::kNull;
  bool boolean = false;
  std::string text;  // a number's text or a string's value
  std::vector<JsonValue> items;                            // array
  std::vector<std::pair<std::string, JsonValue>> members;  // object, in file order

  // The member `key` of an object; nullptr when absent or not an object.
  const JsonValue* Find(const std::string& key) const;
};

// Parses `text` (one value, whitespace around it); false with *error
// ("byte N: ...") when it is not JSON.
bool ParseJson(const std::string& text, JsonValue* value, std::string* error);

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_JSON_VALUE_H_
