// SPDX-License-Identifier: MIT
// The metrics are public (cbrdf/metrics.h); the library's sources include them under this name.
#pragma once

#include "cbrdf/metrics.h"
