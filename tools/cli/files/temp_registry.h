// SPDX-License-Identifier: MIT
// Names of temporary files being written, kept where a signal handler can remove them.
//
// A fixed table of slots (no allocation, no locks), so that the handler only reads memory that is
// always valid and calls unlink, both async-signal-safe.
#pragma once

#include <atomic>
#include <cstddef>
#include <string>

namespace cbrdf::cli {

// The temporary's file name for a target named target_name: `.NAME.cbrdf-tmp-PID-N`, with NAME cut
// (at a UTF-8 character boundary) so that the whole fits in max_name bytes.
std::string temporary_name(const std::string& target_name, std::size_t max_name, long pid,
                           unsigned counter);

namespace temp_registry {

// Registers a path; returns its slot, or -1 when every slot is taken (then no handler removes it;
// the write still works).
int add(const char* path);
// Forgets a slot (no-op for -1).
void remove(int slot);
// Unlinks every registered path; async-signal-safe.
void unlink_all();
// See remove_temporaries_on_signals in cbrdf/file_io.h.
void install_signal_handlers();
// See interrupt_sets_flag in files/file_io.h.
void interrupt_sets(std::atomic<bool>* flag);

}  // namespace temp_registry
}  // namespace cbrdf::cli
