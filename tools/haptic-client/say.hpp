#pragma once  // SPDX-License-Identifier: Apache-2.0
// The haptic client's lines on standard output, written by a thread of their own once
// start_saying() was called: the device loop, which renders the force the hand feels, never waits
// for a terminal whose output was stopped (Ctrl-S) or for a pipe nobody reads. Before it (and in
// the devices' tests) say() writes at once.
namespace viscera::haptic {

/// printf-like; one line (the newline is added).
void say(const char* format, ...) __attribute__((format(printf, 1, 2)));
void start_saying();
/// Writes the lines still queued (waiting for the output as long as it takes), then says at once again.
void stop_saying();

}  // namespace viscera::haptic
