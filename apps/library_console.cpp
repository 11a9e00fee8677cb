// The process-wide settings main makes once: the version it reports and the libraries' consoles.

#include <pcl/console/print.h>

#include "commands.hpp"

namespace pitchlab::apps {

const char* Version() { return PITCHLAB_VERSION; }

void SilenceLibraryConsoles() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }

}  // namespace pitchlab::apps
