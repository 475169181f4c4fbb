#pragma once
// Instance id lists as users type them ("0,2,5-9", "all") for the flatten
// what-if: parsed and checked in one place for the CLI (`flatten
// --instances`), the GUI's Flatten panel and the `flatten` script command.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace accelviz {

/// "0,2,5-9" (ids and inclusive ranges, separated by commas or spaces) or
/// "all" → sorted, distinct instance ids, each < COUNT. Throws
/// std::invalid_argument with a one-line message naming the bad item; an
/// empty item between commas ("0,,1", "0,") is one (a typo, not a list).
std::vector<std::uint32_t> parse_instance_ids(std::string_view text, std::size_t count);

/// The syntax of an id list alone (no instance count yet): throws what
/// parse_instance_ids would for a malformed item.
void check_instance_ids(std::string_view text);

/// IDS back as text, runs of consecutive ids as ranges ("0,2,5-9").
std::string format_instance_ids(const std::vector<std::uint32_t>& ids);

}  // namespace accelviz
