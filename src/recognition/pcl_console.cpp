#include "recognition/pcl_console.h"

#include <pcl/console/print.h>

namespace pb {

void silence_pcl_console() {
  static const bool done = [] {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    return true;
  }();
  (void)done;
}

}  // namespace pb
