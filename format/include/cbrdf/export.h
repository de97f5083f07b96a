// SPDX-License-Identifier: MIT
// Symbol visibility of the shared libraries: they are built with hidden visibility, and only what
// the installed headers declare with CBRDF_EXPORT is exported. CBRDF_INTERNAL_EXPORT marks internal
// functions that one of cbrdf's own shared libraries calls in another (the encoder in the decoder);
// they are declared only in headers that are not installed and are not part of the API.
#pragma once

#if (defined(__GNUC__) || defined(__clang__)) && defined(__cplusplus)
// The standard attribute form, so that it sits beside [[nodiscard]] on a class.
#define CBRDF_EXPORT [[gnu::visibility("default")]]
#elif defined(__GNUC__) || defined(__clang__)
#define CBRDF_EXPORT __attribute__((visibility("default")))
#else
#define CBRDF_EXPORT
#endif
#define CBRDF_INTERNAL_EXPORT CBRDF_EXPORT
