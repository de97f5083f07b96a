/* SPDX-License-Identifier: MIT */
/** @file
 * The one export macro of the cbrdf C API (cbrdf/cbrdf_decode.h, cbrdf/cbrdf_encode.h).
 *
 * CBRDF_C_API marks every function of the stable C interface, the only symbols the shared
 * libraries export:
 * - GCC and clang: default visibility (the libraries are built with -fvisibility=hidden).
 * - Windows: __declspec(dllexport) while building the DLLs (CBRDF_BUILDING defined),
 *   __declspec(dllimport) for a consumer of them (CBRDF_SHARED_LIB defined), nothing for the
 *   static libraries.
 * A consumer may define CBRDF_C_API itself before including any cbrdf header.
 *
 * CBRDF_C_DEPRECATED(msg) marks a function kept for existing callers only; define
 * CBRDF_NO_DEPRECATION_WARNINGS to silence it. */
#ifndef CBRDF_CBRDF_C_EXPORT_H_
#define CBRDF_CBRDF_C_EXPORT_H_

#ifndef CBRDF_C_API
#if defined(_WIN32) || defined(__CYGWIN__)
#if defined(CBRDF_BUILDING)
#define CBRDF_C_API __declspec(dllexport)
#elif defined(CBRDF_SHARED_LIB)
#define CBRDF_C_API __declspec(dllimport)
#else
#define CBRDF_C_API
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define CBRDF_C_API __attribute__((visibility("default")))
#else
#define CBRDF_C_API
#endif
#endif /* CBRDF_C_API */

#ifndef CBRDF_C_DEPRECATED
#if defined(CBRDF_NO_DEPRECATION_WARNINGS)
#define CBRDF_C_DEPRECATED(msg)
#elif defined(__GNUC__) || defined(__clang__)
#define CBRDF_C_DEPRECATED(msg) __attribute__((deprecated(msg)))
#elif defined(_MSC_VER)
#define CBRDF_C_DEPRECATED(msg) __declspec(deprecated(msg))
#else
#define CBRDF_C_DEPRECATED(msg)
#endif
#endif /* CBRDF_C_DEPRECATED */

#endif /* CBRDF_CBRDF_C_EXPORT_H_ */
