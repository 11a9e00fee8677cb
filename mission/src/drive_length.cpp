#include "drive_length.hpp"

#include <algorithm>

namespace pitchlab::mission {

DriveLength PlanDriveLength(double drive_per_stop_m, double unknown_margin_m, double plan_known_m,
                            bool seen_to_the_end, bool last_turned_only,
                            std::optional<double> plan_to_doubt_m) {
  DriveLength drive;
  drive.length_m = std::min(drive_per_stop_m, seen_to_the_end ? plan_known_m
                                                              : plan_known_m - unknown_margin_m);
  if (seen_to_the_end && !plan_to_doubt_m) return drive;
  drive.turn_only = drive.length_m < unknown_margin_m && !last_turned_only;
  if (drive.turn_only) return drive;
  if (last_turned_only) drive.length_m = std::max(drive.length_m, std::min(drive_per_stop_m, 1.0));
  if (plan_to_doubt_m) drive.length_m = std::min(drive.length_m, *plan_to_doubt_m - unknown_margin_m);
  return drive;
}

}  // namespace pitchlab::mission
