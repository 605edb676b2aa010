#pragma once

#include <string>

#include "viewer/view_page.h"

namespace tubepick::cli {

/// Colour of label `i` as "#rrggbb": ten well-separated colours (Tableau 10), then hues by the
/// golden angle; a negative label is light grey.
std::string PaletteColour(int i);

/// Escapes &, <, > and quotes for SVG / XML text and attributes (the viewer's HTML escaping).
inline std::string XmlEscape(const std::string& text) { return viewer::HtmlEscape(text); }

}  // namespace tubepick::cli
