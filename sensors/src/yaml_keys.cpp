#include "pitchlab/sensors/yaml_keys.hpp"

#include <map>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace pitchlab::sensors {
namespace {

void CheckUniqueKeys(const YAML::Node& node, const std::string& path, const std::string& source) {
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) CheckUniqueKeys(node[i], path, source);
  }
  if (!node.IsMap()) return;
  std::map<std::string, int> first_line;
  for (const auto& kv : node) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "<non-scalar key>";
    const std::string name = path.empty() ? key : path + "." + key;
    const int line = kv.first.Mark().line + 1;
    if (auto [it, fresh] = first_line.emplace(key, line); !fresh) {
      throw std::invalid_argument(source + ": " + name + " is given twice (lines " +
                                  std::to_string(it->second) + " and " + std::to_string(line) +
                                  "); keep one");
    }
    CheckUniqueKeys(kv.second, name, source);
  }
}

}  // namespace

void CheckUniqueYamlKeys(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception&) {
    return;  // the caller's parser names the syntax error
  }
  CheckUniqueKeys(root, "", source);
}

}  // namespace pitchlab::sensors
