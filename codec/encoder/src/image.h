// SPDX-License-Identifier: MIT
// The image type is public (cbrdf/image.h); the library's sources include it under this name.
#pragma once

#include "cbrdf/image.h"
