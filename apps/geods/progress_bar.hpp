#pragma once
// A one-line progress bar on stderr for terminals.
#include "geods/core/progress.hpp"

namespace geods::cli {

/// A callback drawing "stage [#####     ] 42%" on stderr when stderr is a
/// terminal; an empty callback otherwise, so pipes and logs stay clean.
ProgressCallback terminal_progress_bar();

}  // namespace geods::cli
