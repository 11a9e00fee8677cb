#pragma once
// The laser rig's configuration as one aggregate, loadable from and printable to YAML.

#include <string>

#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/pitch_unit.hpp"
#include "pitchlab/sensors/pitching_scanner.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors {

/// Everything that shapes a 3D scan. Angles in the YAML are degrees, lengths metres.
struct SensorConfig {
  Lms200Config lms200;
  PitchUnitConfig pitch_unit;
  ScanPatternConfig scan;
  MountConfig mount;

  /// Validates every part; throws std::invalid_argument naming the field.
  void Validate() const;
};

/// Reads the sections `lms200`, `pitch_unit`, `scan`, `mount` of a YAML document over the
/// defaults; other top-level sections belong to other modules and are left alone. A key unknown
/// inside these sections, a wrong type or an invalid value throws std::invalid_argument naming
/// `source`, the field and the value; so does a key given twice anywhere in the document (every
/// config is read through here first, so this is the one place that checks it).
SensorConfig ParseSensorConfig(const std::string& yaml_text, const std::string& source);

/// The same sections as YAML (degrees, metres), readable back by ParseSensorConfig.
std::string SensorConfigToYaml(const SensorConfig& config);

}  // namespace pitchlab::sensors
