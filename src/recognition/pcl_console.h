// PCL's console messages (OUR-CVFH's "both axes are equally easy/difficult to
// disambiguate", CVFH's "no clusters were found", the RANSAC inside Hough
// grouping's "no samples could be selected") would flood stderr and the
// runner's worker log. Every PCL result is checked by its caller instead.
// PCL-free header; make_method calls it before any method runs.
#pragma once

namespace pb {
void silence_pcl_console();  // idempotent, thread-safe
}
