#include "core/base/quote.h"

namespace armfault {

std::string EscapeMarkup(std::string_view text, MarkupQuotes quotes) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += quotes == MarkupQuotes::kKeep ? "\"" : "&quot;"; break;
      case '\'': out += quotes == MarkupQuotes::kKeep ? "'" : quotes == MarkupQuotes::kXml ? "&apos;" : "&#39;"; break;
      default: out += (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') ? '?' : c;
    }
  }
  return out;
}

std::string ShellQuote(std::string_view s) {
  if (!s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789/._-=:") == std::string_view::npos) {
    return std::string(s);
  }
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace armfault
