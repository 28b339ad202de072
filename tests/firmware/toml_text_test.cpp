// The text check in front of toml++ (TomlReader): toml++ 3.3.0 has undefined behaviour on a non-ASCII code
// point where it looks for whitespace (marzer/tomlplusplus#295), so loomctl refuses non-ASCII outside
// strings and comments, and invalid UTF-8 anywhere, before toml++ sees the text — naming file:line:col and
// the code point. Non-ASCII inside strings and comments (names, notes) stays allowed.
#include <gtest/gtest.h>

#include <string>

#include "config_error.hpp"
#include "loom/config/config.hpp"

using namespace loom::firmware;

namespace {

using loom::test::config_error;
using loom::test::scene_error;
const std::string kHead = "extends = \"default\"\n";
}  // namespace

TEST(TomlText, NoBreakSpaceBetweenKeyAndEqualsIsRefused) {
  // Line 3 is "width_m<U+00A0>= 1.2": the no-break space is the 8th character.
  EXPECT_EQ(config_error(kHead + "[loom]\nwidth_m\xC2\xA0= 1.2\n"),
            "loom.toml:3:8: non-ASCII character U+00A0 outside a string or comment");
}

TEST(TomlText, NonAsciiValueIsRefusedWithItsCodePoint) {
  // The fuzzers' reproducer: `x = χ` reached __builtin_unreachable() in toml++ 3.3.0.
  EXPECT_EQ(config_error("x = \xCF\x87\n"),
            "loom.toml:1:5: non-ASCII character U+03C7 outside a string or comment");
  EXPECT_EQ(scene_error("name = \"x\"\ncode = \xCF\x87"
                        "8611\n"),
            "scene.toml:2:8: non-ASCII character U+03C7 outside a string or comment");
  // A 3- and a 4-byte code point after a value, and one in a table header.
  EXPECT_EQ(config_error(kHead + "[loom]\nwidth_m = 1.2 \xE3\x80\x80\n"),
            "loom.toml:3:15: non-ASCII character U+3000 outside a string or comment");
  EXPECT_EQ(config_error(kHead + "[loom]\nwidth_m = 1.2\xF0\x9F\xA7\xB6\n"),
            "loom.toml:3:14: non-ASCII character U+1F9F6 outside a string or comment");
  EXPECT_EQ(config_error("[lo\xC3\xB6m]\n"),
            "loom.toml:1:4: non-ASCII character U+00F6 outside a string or comment");
}

TEST(TomlText, NonAsciiInsideStringsIsAccepted) {
  // U+0131 (dotless i) is one of the code points toml++ 3.3.0 trips on outside a string.
  EXPECT_EQ(parse_loom_config(kHead + "[loom]\nid = \"hal\xC4\xB1"
                                      "1\"\n",
                              "loom.toml")
                .loom_id,
            "hal\xC4\xB1"
            "1");
  EXPECT_EQ(parse_loom_config(kHead + "[loom]\nid = 'hal\xC4\xB1"
                                      "2'\n",
                              "loom.toml")
                .loom_id,
            "hal\xC4\xB1"
            "2");
  // Multi-line basic and literal strings, with escapes and quotes inside (a scene's name is free text).
  const auto scene_name = [](const std::string& value) {
    return parse_scene("name = " + value + "\neffects = [\"ideal\"]\n", "scene.toml").spec.name;
  };
  EXPECT_EQ(scene_name("\"\"\"\xCF\x87\\\"\xCF\x87\"\"\xCF\x87\"\"\"\""), "\xCF\x87\"\xCF\x87\"\"\xCF\x87\"");
  EXPECT_EQ(scene_name("'''\xCF\x87''\xCF\x87'''"), "\xCF\x87''\xCF\x87");
  EXPECT_EQ(scene_name("\"\"\"\n\xC3\xA9\"\"\" # \xC3\xA9"), "\xC3\xA9");
  // A string ending in an escaped backslash, then a comment with non-ASCII.
  EXPECT_EQ(scene_name("\"a\\\\\" # \xCF\x87"), "a\\");
  EXPECT_EQ(scene_name("'a\\' # \xCF\x87"), "a\\");
  // A quoted key with non-ASCII is read (and refused as unknown); toml++ counts columns in characters and
  // the value is shown as written.
  EXPECT_EQ(config_error(kHead + "[loom]\n\"\xCF\x87\" = 1\n"),
            "loom.toml:3:7: loom.\xCF\x87 = 1: unknown field");
  // A byte order mark at the start is fine.
  EXPECT_EQ(parse_loom_config("\xEF\xBB\xBF" + kHead, "loom.toml").loom_id, "loom1");
}

TEST(TomlText, NonAsciiInsideCommentsIsAccepted) {
  const LoomConfig c =
      parse_loom_config("# Webstuhl f\xC3\xBCr Teppiche \xE2\x80\x94 \xCF\x87\xC2\xA0\xE3\x80\x80\n" + kHead +
                            "[loom]   # \xC3\xB6\nwidth_m = 1.3 #\xC2\xA0\xCF\x87\n",
                        "loom.toml");
  EXPECT_DOUBLE_EQ(c.profile.width_m, 1.3);
}

TEST(TomlText, InvalidUtf8IsRefusedAnywhere) {
  // In a comment, in a string and outside both.
  EXPECT_EQ(config_error("# caf\xE9\n"),
            "loom.toml:1:6: invalid UTF-8: sequence starting with 0xE9 cut short");
  EXPECT_EQ(config_error(kHead + "[loom]\nid = \"a\xFF\"\n"),
            "loom.toml:3:8: invalid UTF-8: byte 0xFF never starts a character");
  EXPECT_EQ(config_error("x = \x80\n"), "loom.toml:1:5: invalid UTF-8: stray continuation byte 0x80");
  // Overlong, surrogate, beyond U+10FFFF, truncated at the end of the file.
  EXPECT_EQ(config_error("# \xE0\x80\xAF\n"), "loom.toml:1:3: invalid UTF-8: overlong encoding of U+002F");
  EXPECT_EQ(config_error("# \xC0\xAF\n"), "loom.toml:1:3: invalid UTF-8: byte 0xC0 never starts a character");
  EXPECT_EQ(config_error("# \xED\xA0\x80\n"), "loom.toml:1:3: invalid UTF-8: encoded surrogate U+D800");
  EXPECT_EQ(config_error("# \xF4\x90\x80\x80\n"), "loom.toml:1:3: invalid UTF-8: code point beyond U+10FFFF");
  EXPECT_EQ(config_error("# \xF0\x9F\xA7"),
            "loom.toml:1:3: invalid UTF-8: sequence starting with 0xF0 cut short");
}

TEST(TomlText, LineAndColumnCountCharactersNotBytes) {
  // Three 2-byte characters inside a string before the offending one: the column counts characters.
  EXPECT_EQ(config_error(kHead + "[loom]\n\n\nid = \"\xC3\xA4\xC3\xB6\xC3\xBC\" \xC2\xA0# x\n"),
            "loom.toml:5:12: non-ASCII character U+00A0 outside a string or comment");
  // Tabs count as one column, CRLF line ends count one line.
  EXPECT_EQ(config_error("a = 1\r\n\tb = 2\r\n\t\t\xC2\xA0\r\n"),
            "loom.toml:3:3: non-ASCII character U+00A0 outside a string or comment");
  // A multi-line string's lines are counted; the text after it is outside again.
  EXPECT_EQ(config_error("a = \"\"\"\n\xC2\xA0\n\"\"\"\"\" \xC2\xA0\n"),
            "loom.toml:3:7: non-ASCII character U+00A0 outside a string or comment");
  EXPECT_EQ(config_error("a = '''\n\xC2\xA0\n''''' \xC2\xA0\n"),
            "loom.toml:3:7: non-ASCII character U+00A0 outside a string or comment");
  // A single-line string left open ends at the line end: the next line is outside.
  EXPECT_EQ(config_error("a = \"open\n\xC2\xA0\n"),
            "loom.toml:2:1: non-ASCII character U+00A0 outside a string or comment");
}

TEST(TomlText, WhitespaceLookupsInsideMultiLineStringsAreRefused) {
  // toml++ asks "is this whitespace?" of the character after a backslash and of the first character after a
  // line-ending backslash: there a non-ASCII code point is refused too.
  EXPECT_EQ(config_error("a = \"\"\"\\\xCF\x87\"\"\"\n"),
            "loom.toml:1:9: non-ASCII character U+03C7 after a backslash in a string (not a TOML escape)");
  EXPECT_EQ(config_error("a = \"\\\xCF\x87\"\n"),
            "loom.toml:1:7: non-ASCII character U+03C7 after a backslash in a string (not a TOML escape)");
  EXPECT_EQ(
      config_error("a = \"\"\"\\  \xCF\x87\n\"\"\"\n"),
      "loom.toml:1:11: non-ASCII character U+03C7 after a line-ending backslash (only spaces and tabs may "
      "follow it on its line)");
  EXPECT_EQ(
      config_error("a = \"\"\"x\\\n\n   \xC3\xA9t\xC3\xA9\"\"\"\n"),
      "loom.toml:3:4: non-ASCII character U+00E9 first after a line-ending backslash (toml++ 3.3.0 cannot "
      "parse it there; write it as \\u00E9)");
  EXPECT_EQ(
      config_error("a = \"\"\"x\\ \t\r\n \t\r\n\xC3\xA9\"\"\"\n"),
      "loom.toml:3:1: non-ASCII character U+00E9 first after a line-ending backslash (toml++ 3.3.0 cannot "
      "parse it there; write it as \\u00E9)");
  // After the first character the rest of the line is ordinary string content again.
  EXPECT_EQ(parse_loom_config(kHead + "[loom]\nid = \"\"\"\\\n  x\xC3\xA9\\\n  \\u00E9\xC3\xA9\"\"\"\n",
                              "loom.toml")
                .loom_id,
            "x\xC3\xA9\xC3\xA9\xC3\xA9");
}

TEST(TomlText, FuzzReproducersAreRefusedBeforeToml) {
  // The fuzzers' reproducers (now in the seed corpora): refused by the text check, not by toml++.
  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/tests/fuzz/corpus/";
  try {
    (void)load_loom_config(dir + "loom_config/toml_unreachable_U03C7.toml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "toml_unreachable_U03C7.toml:1:5: non-ASCII character U+03C7 outside a string "
                  "or comment"),
              std::string::npos)
        << e.what();
  }
  try {
    (void)load_scene(dir + "scene/toml_unreachable_U03C7.toml");
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "toml_unreachable_U03C7.toml:7:8: non-ASCII character U+03C7 outside a string "
                  "or comment"),
              std::string::npos)
        << e.what();
  }
}

// Found by fuzz_loom_config: a quote in the middle of a bare token (`x"=χ`) is not the start of a
// string — TOML has none there, yet toml++ walks on to the χ — so it must not hide what follows it.
TEST(TomlText, AQuoteInsideABareTokenDoesNotOpenAString) {
  EXPECT_EQ(config_error("key =----x\"=\xCF\x87\n"),
            "loom.toml:1:13: non-ASCII character U+03C7 outside a string or comment");
  EXPECT_EQ(config_error("a = \"x\" \"\xCF\x87\"\n"),
            "loom.toml:1:10: non-ASCII character U+03C7 outside a string or comment");
  // Where TOML does open strings: after = [ , { . and at the start of a line (a quoted key).
  EXPECT_EQ(config_error(kHead + "[loom]\nloom_id = \"\xCF\x87\"\n").find("non-ASCII"), std::string::npos);
  EXPECT_EQ(config_error(kHead + "\"\xCF\x87\" = 1\n").find("non-ASCII"), std::string::npos);
  EXPECT_EQ(config_error(kHead + "[loom]\nx = [\"a\", \"\xCF\x87\"]\n").find("non-ASCII"), std::string::npos);
  EXPECT_EQ(config_error(kHead + "[loom]\nx = { y = \"\xCF\x87\" }\n").find("non-ASCII"), std::string::npos);
  // A bare value runs to whitespace , ] }: an '=' inside it does not start a value (toml++ walks on).
  EXPECT_EQ(config_error("key =--x=\"\x16=\xCF\x85\n"),
            "loom.toml:1:13: non-ASCII character U+03C5 outside a string or comment");
  EXPECT_EQ(config_error(kHead + "[loom]\nx = {a=\"\xCF\x87\", b=\"\xCF\x87\"}\n").find("non-ASCII"),
            std::string::npos);
  const std::string dir = std::string(LOOM_SOURCE_DIR) + "/tests/fuzz/corpus/loom_config/";
  EXPECT_THROW((void)load_loom_config(dir + "toml_unreachable_quote_inside_a_bare_token.toml"), ConfigError);
  EXPECT_THROW((void)load_loom_config(dir + "toml_unreachable_quote_inside_a_bare_value.toml"), ConfigError);
}
