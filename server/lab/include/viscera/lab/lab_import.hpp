#pragma once  // SPDX-License-Identifier: Apache-2.0
// viscera-lab import: a test machine's export (force against displacement over time, in the
// machine's own units and column names) turned into a data set (dataset.hpp). The conversion to
// strain and stress, and the units it assumed, are written into dataset.json ("import"), so that
// what the lab fits can be traced back to the files a researcher measured.
//  - uniaxial: strain = displacement / length, stress = force / (width x thickness) (nominal);
//  - simple shear: strain = displacement / thickness, stress = force / (length x width).
#include <map>
#include <string>
#include <vector>

#include "viscera/lab/dataset.hpp"

namespace viscera::lab {

/// A column of the export and the factor that takes its unit to SI.
struct ImportColumn {
  std::string name;
  std::string unit;
  double to_si = 1.0;
};

enum class ImportQuantity { time, force, displacement };

/// "COLUMN" or "COLUMN:UNIT" (time: s, ms, min, h; force: N, mN, kN; displacement: m, mm, um);
/// without a unit, SI. Throws common::UsageError naming `flag` on an unknown unit or an empty name.
ImportColumn parse_import_column(const std::string& flag, const std::string& text, ImportQuantity q);

struct ImportOptions {
  std::string name;  ///< the data set's name ("" : the output folder's)
  Mode mode = Mode::uniaxial;
  Control control = Control::strain;
  Specimen specimen;
  ImportColumn time{"time", "s", 1.0}, force{"force", "N", 1.0}, displacement{"displacement", "m", 1.0};
  /// A preload taken off: each export's force at rest (the mean over its leading rows whose
  /// displacement is the first row's; at least the first row, whose noise a single row carries
  /// into the whole test) is subtracted from all of its forces, as a machine's "zero force"
  /// button does, so that the test starts at zero stress.
  bool tare = false;
  /// Displacements from each export's first row instead of the export's own zero.
  bool zero_displacement = false;
  /// Compressed between platens it is not bonded to (dataset.json "contact": "platens").
  bool platens = false;
  /// What each test starts from (dataset.json "history"): carried, the exports in the order given
  /// being the session's on one specimen; or reset, each on an untouched specimen.
  History history = History::carried;
  /// The exports count compression as positive force and displacement: both are negated (the data
  /// set's compression is negative strain and stress).
  bool compression_positive = false;
  /// Each export's own specimen where it differs from `specimen` (read_specimen_table), by the
  /// export's file name as given (its last path component).
  std::map<std::string, Specimen> specimen_of;
};

/// A lab's table of specimens: a CSV with a header row, a column `file` naming each export (its
/// file name) and any of length_m, width_m, thickness_m, density_kg_m3; an empty cell keeps
/// `defaults`' value. Throws common::InputError naming the table, the row and the column (an
/// unknown column, a value outside (0, 10] m or (0, 1e5] kg/m^3, a file named twice).
std::map<std::string, Specimen> read_specimen_table(const std::string& path, const Specimen& defaults);

/// What import_test took off an export (SI): its first force and first displacement, 0 when not asked.
struct ImportOffsets {
  double force_n = 0.0, displacement_m = 0.0;
};

/// One export as a test: the file separated by commas, semicolons or tabs (the first line's most
/// frequent one), a header row naming the columns, empty lines skipped. Throws common::InputError
/// naming the file, the line and the column.
TestData import_test(const std::string& path, const ImportOptions& o, ImportOffsets* taken_off = nullptr);

/// The exports `files` as a data set in `folder`: one CSV per file (named after it), dataset.json
/// with the conversion under "import" (with each test's tare and displacement zero); then read back with read_dataset, so that every check a
/// data set gets (units that cannot be right, times that do not increase) applies. Refuses a
/// folder that already holds a dataset.json, and two files with the same name.
Dataset import_dataset(const std::vector<std::string>& files, const ImportOptions& o, const std::string& folder);

}  // namespace viscera::lab
