// Text quoted for another language: markup (HTML, XML, Markdown) and the POSIX shell. CSV cells
// are core/base/csv.h's (CsvText).
#pragma once

#include <string>
#include <string_view>

namespace armfault {

// How EscapeMarkup writes the quotes " and '.
enum class MarkupQuotes {
  kHtml,  // &quot; and &#39;: HTML text and attributes
  kXml,   // &quot; and &apos;: XML text and attributes
  kKeep,  // as they are: Markdown text, where they are literal
};

// Text safe inside an element or a quoted attribute: & < > as &amp; &lt; &gt;, the quotes as
// `quotes` says, and the control characters that HTML and XML 1.0 refuse (all below 0x20 but
// tab, line feed and carriage return) as '?'.
std::string EscapeMarkup(std::string_view text, MarkupQuotes quotes);

// A word the shell reads back as `s`: as it is when it holds only letters, digits and / . _ - = :,
// else in single quotes (a ' inside as '\''; the empty word as '').
std::string ShellQuote(std::string_view s);

}  // namespace armfault
