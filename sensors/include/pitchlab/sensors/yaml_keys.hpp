#pragma once
// A YAML key given twice: yaml-cpp keeps every pair of a mapping and `node[key]` answers the
// first, so a value a user appended to change a setting would be dropped without a word. Every
// pitchlab config reader checks its text with this first.

#include <string>

namespace pitchlab::sensors {

/// Throws std::invalid_argument naming `source`, the key (dotted path) and both lines when a
/// mapping anywhere in `yaml_text` gives a key twice. Text that is not valid YAML passes: the
/// caller's parser reports that in its own words.
void CheckUniqueYamlKeys(const std::string& yaml_text, const std::string& source);

}  // namespace pitchlab::sensors
