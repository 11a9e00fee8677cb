#include "pitchlab/sim/world.hpp"

#include <mujoco/mujoco.h>

#include <regex>
#include <stdexcept>

namespace pitchlab::sim {
namespace {

[[noreturn]] void Bad(const std::string& source, const std::string& what) {
  throw std::runtime_error("world " + source + ": " + what);
}

int CountOf(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

bool IsAbsolute(const std::string& path) { return !path.empty() && path.front() == '/'; }

std::string Join(const std::string& dir, const std::string& file) {
  if (dir.empty()) return file;
  return dir.back() == '/' ? dir + file : dir + "/" + file;
}

// The <compiler> attribute `name`, or empty.
std::string CompilerAttribute(const std::string& xml, const std::string& name) {
  std::smatch compiler;
  if (!std::regex_search(xml, compiler, std::regex(R"(<compiler\b[^>]*>)"))) return {};
  std::smatch attr;
  const std::string tag = compiler.str();
  if (!std::regex_search(tag, attr, std::regex("\\b" + name + R"(\s*=\s*["']([^"']*)["'])"))) {
    return {};
  }
  return attr[1].str();
}

// Makes compiler meshdir/texturedir absolute and every relative file="" absolute, matching
// MuJoCo 2.2's resolution: mesh, skin and hfield files under meshdir, textures under texturedir,
// everything else (include) under the model's folder.
std::string AbsolutizePaths(const std::string& xml, const std::string& world_dir) {
  const std::string meshdir = CompilerAttribute(xml, "meshdir");
  const std::string texturedir = CompilerAttribute(xml, "texturedir");
  const std::regex tag_re(R"(<(\w+)\b([^>]*)>)");
  const std::regex attr_re(R"(\b(file|meshdir|texturedir)(\s*=\s*)(["'])([^"']*)\3)");
  auto resolve = [&](const std::string& tag, const std::string& attr, const std::string& value) {
    if (IsAbsolute(value)) return value;
    const bool under_meshdir = tag == "mesh" || tag == "skin" || tag == "hfield";
    if (attr == "file" && under_meshdir && !meshdir.empty()) return value;  // absolute meshdir
    if (attr == "file" && tag == "texture" && !texturedir.empty()) return value;
    return Join(world_dir, value);
  };
  std::string out;
  auto begin = xml.cbegin();
  std::smatch tag;
  while (std::regex_search(begin, xml.cend(), tag, tag_re)) {
    out.append(begin, tag[2].first);
    const std::string name = tag[1].str(), attrs = tag[2].str();
    auto a_begin = attrs.cbegin();
    std::smatch a;
    while (std::regex_search(a_begin, attrs.cend(), a, attr_re)) {
      out.append(a_begin, a[4].first);
      out.append(resolve(name, a[1].str(), a[4].str()));
      a_begin = a[4].second;
    }
    out.append(a_begin, attrs.cend());
    begin = tag[2].second;
  }
  out.append(begin, xml.cend());
  return out;
}

}  // namespace

std::string ComposeWorldXml(const std::string& world_xml, const std::string& world_dir,
                            const RobotConfig& robot, const std::string& source_name) {
  const RobotMjcf parts = MakeRobotMjcf(robot);
  std::string xml = AbsolutizePaths(world_xml, world_dir);
  if (std::regex_search(xml, std::regex(R"(<body\b[^>]*\bname\s*=\s*["']robot["'])"))) {
    Bad(source_name, "already has a body named \"robot\"; worlds must not contain the robot");
  }
  const std::size_t root_end = xml.rfind("</mujoco>");
  if (root_end == std::string::npos) Bad(source_name, "has no </mujoco> root element");

  // Splice the body into <worldbody> (or expand a self-closing <worldbody/>).
  const std::size_t wb_end = xml.rfind("</worldbody>");
  std::smatch empty_wb;
  if (wb_end != std::string::npos) {
    xml.insert(wb_end, parts.body);
  } else if (std::regex_search(xml, empty_wb, std::regex(R"(<worldbody\s*/>)"))) {
    const auto pos = static_cast<std::size_t>(empty_wb.position(0));
    xml.replace(pos, empty_wb.length(0), "<worldbody>\n" + parts.body + "</worldbody>");
  } else {
    Bad(source_name, "has no <worldbody> element");
  }
  // The robot's wheels add contacts (cylinders on heightfields give several each): size MuJoCo
  // 2.2's contact buffer for the robot unless the world sizes it itself: at most mjMAXCONPAIR
  // (50) contacts for each of the robot's geoms (a P3-AT has 8), at most 4 constraint rows each
  // (a pyramidal cone of condim 3). No more: 2.2 sizes its solver stack as 5 njmax^2 numbers,
  // cleared when a model's data is made (the former njmax 4000 made it 640 MB, 1.0 s for each
  // Simulation; the terrain world's most was 20 contacts, 60 rows).
  const int contacts = mjMAXCONPAIR * CountOf(parts.body, "<geom ");
  const std::string size = xml.find("nconmax") == std::string::npos
                               ? "<size nconmax=\"" + std::to_string(contacts) + "\" njmax=\"" +
                                     std::to_string(4 * contacts) + "\"/>\n"
                               : "";
  const std::size_t close = xml.rfind("</mujoco>");
  xml.insert(close, size + parts.defaults + parts.actuators + parts.sensors);
  return xml;
}

}  // namespace pitchlab::sim
