// The design book (designs.json): the row each design has reached. It credits rows to the right design
// across restarts and power cuts, and refuses what it cannot explain; the expected files are written out
// by hand.
#include "loom/state/design_book.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "loom/config/config.hpp"
#include "test_dir.hpp"

namespace {

class DesignBookTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = loom::test::fresh_test_dir("design_book");
    path_ = (dir_ / "designs.json").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& text) { std::ofstream(path_) << text; }
  std::string read() {
    std::ifstream in(path_);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(DesignBookTest, EachDesignResumesWhereItWasLeft) {
  loom::state::DesignBook book(path_);
  EXPECT_EQ(book.activate("a.csv", 10), 0u);  // production row 10, design a starts
  book.record(11);
  book.record(12);
  EXPECT_EQ(book.rows_done(), 2u);
  loom::state::DesignBook again(path_);
  EXPECT_EQ(again.activate("b.png", 12), 0u);
  again.record(15);
  loom::state::DesignBook back(path_);
  EXPECT_EQ(back.activate("a.csv", 15), 2u);
  EXPECT_EQ(read(), "{\"active\":\"a.csv\",\"at_rows\":15,\"designs\":{\"a.csv\":2,\"b.png\":3}}\n");
}

TEST_F(DesignBookTest, RowsSavedInTheCountersButNotInTheBookGoToTheActiveDesign) {
  // A power cut after the counters' save and before the book's: the counters say 7, the book 5.
  write("{\"active\":\"a.csv\",\"at_rows\":5,\"designs\":{\"a.csv\":4}}");
  loom::state::DesignBook book(path_);
  EXPECT_EQ(book.activate("b.csv", 7), 0u);
  EXPECT_NE(read().find("\"a.csv\":6"), std::string::npos) << read();
}

TEST_F(DesignBookTest, WhatCannotBeExplainedIsRefused) {
  const auto refusal = [&](const std::string& text) -> std::string {
    write(text);
    try {
      loom::state::DesignBook(path_).activate("a.csv", 5);
    } catch (const loom::firmware::ConfigError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(refusal("{\"active\":\"a.csv\",\"at_rows\":9,\"designs\":{\"a.csv\":4}}")
                .find("written at production row 9 but the counters say 5"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":\"a.csv\",\"at_rows\":1,\"designs\":{\"a.csv\":-4}}")
                .find("\"designs\".\"a.csv\" = -4: not a row count"),
            std::string::npos);
  // Row counts are bounded like the production counters they come from: 2^64-1 used to be accepted and wrap.
  EXPECT_NE(refusal("{\"active\":\"a.csv\",\"at_rows\":1,\"designs\":{\"a.csv\":18446744073709551615}}")
                .find("= 18446744073709551615: not a row count in 0..4294967295"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":\"a.csv\",\"at_rows\":1,\"designs\":{\"a.csv\":4294967295}}")
                .find("would pass 4294967295"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":\"a.csv\",\"at_rows\":1.5,\"designs\":{}}").find("\"at_rows\" = 1.5"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":\"z.csv\",\"at_rows\":1,\"designs\":{}}")
                .find("active design 'z.csv' has no entry"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":\"\",\"at_rows\":1,\"designs\":{},\"x\":1}").find("want exactly"),
            std::string::npos);
  EXPECT_NE(refusal("{\"active\":").find(path_ + ": not a design book"), std::string::npos);
  // Nothing was rewritten by a refusal.
  EXPECT_EQ(read(), "{\"active\":");
}

}  // namespace
