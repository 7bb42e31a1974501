#pragma once
// Joint readings from CSV files (docs/models.md section 7). Each row is one posture's readings of
// the movable joints in chain order, comma-separated (or ';' with decimal commas, or tabs:
// CsvDialect, read from the first line; fields may be quoted); the first line may be a header of
// joint names (a line of which no field is a number). Blank lines are skipped. `unit` names the
// unit of the readings of its kind: "deg" (default) or "rad" for the revolute joints, "mm" or "m"
// for the prismatic ones; the joints of the other kind keep their file unit (deg, mm). Every fault
// raises InputError naming the CSV file and the line ("hole_0.csv: line 12: expected 7 numbers, got
// 6").

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "artcal/model/mechanism.hpp"

namespace artcal {

class Node;

/// Units of the readings of one CSV file.
struct ReadingUnits {
  double angle_to_rad = kDegree;  ///< revolute readings times this are rad
  double length_to_mm = 1.0;      ///< prismatic readings times this are mm
};

/// "deg", "rad", "mm", "m" (the other kind of joint in deg or mm), or an angle unit and a length
/// unit joined by "+" ("rad+m", ROS's units; "deg+mm" is "deg"); std::nullopt for anything else.
std::optional<ReadingUnits> readingUnitsFromName(const std::string& name);

/// Which field of a row gives one reading, for files whose columns are not the readings in order
/// (a header naming its columns, docs/plan-format.md "Columns by name"): the header field `name`,
/// or the field at `index` (from 0), or, when `held` is set, no field: every row reads `held`
/// (in the file's unit, like the field would be).
struct CsvColumn {
  std::string name;
  int index = -1;
  std::optional<double> held;
};

/// The `"columns"` member of a plan's CSV entry, `count` entries: a header name ("panda_joint1"),
/// a field's position as "#k" (from 1), or a number, the value every row reads (a joint no file
/// reads). InputError naming the entry's pointer when malformed.
std::vector<CsvColumn> parseCsvColumns(const Node& columns, std::size_t count);

/// How a CSV file separates its fields, read from its first line (the header, or the first
/// row): ';' when the line holds one (a ',' in a field is then a decimal comma, "1,5"); a tab
/// when it holds one and its only commas stand between digits (decimal commas); else ','. A field
/// may be quoted ("j1"): its quotes are not part of it, a separator inside them is.
struct CsvDialect {
  char separator = ',';
  /// "','", "';'" or "tabs", as a message names it.
  std::string name() const;
};
CsvDialect csvDialect(std::string_view first_line);

/// How many fields right of where its header puts them a row's named fields are. The candidate:
/// the shift that puts the header's names, less its trailing empty ones, on the row's last
/// fields; taken when the row's fields at `selected` (header positions) all hold numbers under
/// it, and either they do not as the header stands (a header narrower than its rows), or the
/// header, as wide as the row and ending in as many empty names as the shift, puts fewer names
/// over fields that are not numbers shifted than as it stands (names written left of their
/// values, the values' last fields unnamed). A trailing unnamed column over numbers (an index
/// written last) is not a shift. Else 0 (the reading then names the field that is not a number).
std::size_t headerShift(const std::vector<std::string_view>& header,
                        const std::vector<std::string_view>& row, const std::vector<int>& selected,
                        CsvDialect dialect = {});

/// The fields of a CSV line, each without its surrounding blanks and quotes. `bad_quote`, when
/// given, is set to the first field (from 0) whose opening quote is not closed or whose closing
/// quote is followed by more text, or to -1.
std::vector<std::string_view> csvFields(std::string_view line, CsvDialect dialect = {},
                                        int* bad_quote = nullptr);

/// A field as a number (decimal, a leading '+' allowed; a decimal comma with ';' or tabs), or
/// std::nullopt.
std::optional<double> csvNumber(std::string_view field, CsvDialect dialect = {});

/// A message's hint when `line` holds other separators than the file's: "" when it holds none.
std::string separatorHint(std::string_view line, CsvDialect dialect);

/// Largest number of rows read from one CSV file.
inline constexpr std::size_t kMaxCsvRows = 100'000;
/// Most fields a row of a file whose header names its columns may have.
inline constexpr std::size_t kMaxCsvFields = 1024;

/// The readings of `path` in internal units (rad, mm), one vector per row, for joints of the
/// given kinds. InputError(path, "line N", ...) on any fault; an unreadable or empty file names
/// the file alone. `lines`, when given, receives each row's line number in the file (from 1), for
/// messages about a row that the caller finds wrong.
///
/// `columns`, when given (one per entry of `kinds`), selects each reading's field: a file naming
/// columns by name must start with a header line holding every name selected (once), each row
/// then has as many fields as the header and the fields not selected are ignored. A header whose
/// names, less its trailing empty ones, are fewer than the first row's fields may name that row's
/// last fields (an export that left its leading label fields unnamed: headerShift); every row then
/// has the first row's count. A fault names the
/// line and the column ("line 12: column 5 (\"panda_joint3\"): not a number").
///
/// `dropouts`, when given, allows rows whose readings from entry `dropouts->first` on (an
/// instrument's measured coordinates) are all missing: every such field empty or NaN (a marker a
/// motion-capture system did not see in that frame). Those rows are not returned; their line
/// numbers go to `dropouts->lines`. A row with some of them missing is still refused.
struct CsvDropouts {
  std::size_t first = 0;
  std::vector<long> lines;
};
std::vector<Eigen::VectorXd> readJointCsv(const std::string& path,
                                          const std::vector<JointKind>& kinds,
                                          const ReadingUnits& units,
                                          std::vector<long>* lines = nullptr,
                                          const std::vector<CsvColumn>* columns = nullptr,
                                          CsvDropouts* dropouts = nullptr);

/// The values of the column named `column` in the header of `path` (the file's first line), one
/// per data row with the row's line number (from 1; blank lines skipped as readJointCsv skips
/// them): a probing log's sphere column (docs/plan-format.md, "rows"). InputError naming the
/// file and line when the header has no such column or a row has fewer fields.
std::vector<std::pair<long, std::string>> readCsvColumn(const std::string& path,
                                                        const std::string& column);

}  // namespace artcal
