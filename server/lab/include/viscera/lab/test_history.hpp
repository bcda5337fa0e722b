#pragma once  // SPDX-License-Identifier: Apache-2.0
// A specimen remembers its tests. Where a data set's tests were made on one specimen in the listed
// order (History::carried, dataset.json's default), each test starts in the state the tests before
// it left: the only state the lab's catalogue carries from one test to the next is first-load
// softening's memory, the largest strain seen in tension and in compression (material_model.hpp).
// Relaxation's memory variables are taken as relaxed between tests (a test starts at rest), and
// the platens' contact take-up is a property of each test.
//
// Which tests share a specimen: every test without its own "specimen" in dataset.json was made on
// the data set's specimen; a test with its own was made on another specimen and starts untouched.
// The history of a test comes from the commands of the tests before it, measured or held out: the
// strain command of a strain-controlled test (along its command path, command_path.hpp), the
// measured strain of a stress-controlled one.
#include "viscera/lab/dataset.hpp"

namespace viscera::lab {

/// Sets every test's before_tension and before_compression from the tests before it on its
/// specimen (all zero under History::reset).
void carry_history(Dataset& d);

/// The test as if made on an untouched specimen (the tetrahedral specimen runs each test so).
TestData untouched(TestData t);

}  // namespace viscera::lab
