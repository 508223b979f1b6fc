// core/base/quote.h: markup escaping (junit.xml, report.html, report.md) and shell words.
#include "core/base/quote.h"

#include <gtest/gtest.h>

namespace armfault {
namespace {

TEST(EscapeMarkupTest, EscapesTheMarkupCharactersForEachLanguage) {
  const std::string text = "a<b>&\"c\" 'd'";
  EXPECT_EQ(EscapeMarkup(text, MarkupQuotes::kHtml), "a&lt;b&gt;&amp;&quot;c&quot; &#39;d&#39;");
  EXPECT_EQ(EscapeMarkup(text, MarkupQuotes::kXml), "a&lt;b&gt;&amp;&quot;c&quot; &apos;d&apos;");
  EXPECT_EQ(EscapeMarkup(text, MarkupQuotes::kKeep), "a&lt;b&gt;&amp;\"c\" 'd'");
}

TEST(EscapeMarkupTest, ControlCharactersNeitherLanguageAllowsBecomeQuestionMarks) {
  const std::string text = std::string("x\x01y\tz\n\r") + '\x1f';
  for (MarkupQuotes q : {MarkupQuotes::kHtml, MarkupQuotes::kXml, MarkupQuotes::kKeep}) {
    EXPECT_EQ(EscapeMarkup(text, q), "x?y\tz\n\r?");
  }
  EXPECT_EQ(EscapeMarkup("caf\xc3\xa9", MarkupQuotes::kXml), "caf\xc3\xa9");  // UTF-8 passes
}

TEST(ShellQuoteTest, PlainWordsStayAndOthersAreSingleQuoted) {
  EXPECT_EQ(ShellQuote("out/run-1_a.json"), "out/run-1_a.json");
  EXPECT_EQ(ShellQuote("my campaign.json"), "'my campaign.json'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuote("$(rm -rf ~)"), "'$(rm -rf ~)'");
  EXPECT_EQ(ShellQuote(""), "''");
}

}  // namespace
}  // namespace armfault
