#pragma once

#include <string>

namespace tubepick::cli {

/// Colour of label `i` as "#rrggbb": ten well-separated colours (Tableau 10), then hues by the
/// golden angle; a negative label is light grey.
std::string PaletteColour(int i);

/// Escapes &, <, > and quotes for SVG / XML text and attributes.
std::string XmlEscape(const std::string& text);

}  // namespace tubepick::cli
