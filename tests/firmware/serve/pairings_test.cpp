// Pairing a panel client (issue 30): a hall device guessing codes at full speed neither voids the code
// nor keeps the device the operator is pairing from entering it; its own tries are slowed (1, 2, 4, 8 s)
// and end after five; a token counts only from the device that redeemed it (address and device secret).
#include "loom/firmware/serve/pairings.hpp"

#include <gtest/gtest.h>

#include <string>

using loom::firmware::serve::Pairings;

namespace {
constexpr std::int64_t kNow = 1'800'000'000;
const std::string kTablet = "00112233445566778899aabbccddeeff", kOther = "ffeeddccbbaa99887766554433221100";

std::string wrong_of(const std::string& code) {
  std::string w = code;
  w[0] = w[0] == '9' ? '0' : static_cast<char>(w[0] + 1);
  return w;
}
}  // namespace

TEST(Pairings, AGuesserAtFullSpeedDoesNotKeepAnotherDeviceFromPairing) {
  Pairings p;
  const std::string code = p.new_code("tablet", 12, kNow);
  std::string error;
  // 100 wrong codes a second from 127.0.0.2 for the code's whole life but its last second: only five are
  // judged (1 + 2 + 4 + 8 s of waits between them), the rest are refused unjudged.
  int judged = 0;
  for (std::int64_t t = kNow; t < kNow + Pairings::kCodeLifetimeS - 1; ++t) {
    for (int i = 0; i < 100; ++i) {
      EXPECT_FALSE(p.redeem(wrong_of(code), "127.0.0.2", kOther, t, error));
      if (error.rfind("wrong pairing code", 0) == 0) ++judged;
    }
  }
  EXPECT_EQ(judged, Pairings::kCodeTries);
  EXPECT_NE(error.find("ask for a new code"), std::string::npos) << error;
  // Even the right code from the guesser's address is refused now.
  EXPECT_FALSE(p.redeem(code, "127.0.0.2", kOther, kNow + 118, error));
  // The operator's tablet, in the code's last second, after one typo of its own.
  EXPECT_FALSE(p.redeem(wrong_of(code), "127.0.0.1", kTablet, kNow + 117, error));
  const auto paired = p.redeem(code, "127.0.0.1", kTablet, kNow + Pairings::kCodeLifetimeS - 1, error);
  ASSERT_TRUE(paired) << error;
  EXPECT_EQ(paired->name, "tablet");
  EXPECT_EQ(paired->expires_s, kNow + Pairings::kCodeLifetimeS - 1 + 12 * 3600);
}

TEST(Pairings, WrongTriesWaitLongerEachTimeAndANewCodeStartsAfresh) {
  Pairings p;
  std::string code = p.new_code("tablet", 1, kNow), error;
  std::int64_t t = kNow;
  for (int wait : {1, 2, 4, 8}) {
    EXPECT_FALSE(p.redeem(wrong_of(code), "10.0.0.5", kTablet, t, error));
    EXPECT_NE(error.find("the next in " + std::to_string(wait) + " s"), std::string::npos) << error;
    // Within the wait even the right code is refused, unjudged.
    EXPECT_FALSE(p.redeem(code, "10.0.0.5", kTablet, t + wait - 1, error));
    EXPECT_NE(error.find("wait 1 s"), std::string::npos) << error;
    t += wait;
  }
  EXPECT_FALSE(p.redeem(wrong_of(code), "10.0.0.5", kTablet, t, error));
  EXPECT_NE(error.find("no tries left from this device"), std::string::npos) << error;
  code = p.new_code("tablet", 1, t);
  EXPECT_TRUE(p.redeem(code, "10.0.0.5", kTablet, t, error)) << error;
}

TEST(Pairings, OnlyWrongTriesFromVeryManyAddressesVoidTheCode) {
  Pairings p;
  const std::string code = p.new_code("tablet", 1, kNow);
  std::string error;
  const int addresses = Pairings::kCodeWrongTriesAll / Pairings::kCodeTries;
  for (int a = 0; a < addresses - 1; ++a) {
    for (int k = 0; k < Pairings::kCodeTries; ++k) {
      p.redeem(wrong_of(code), "10.1." + std::to_string(a / 250) + "." + std::to_string(a % 250), kOther,
               kNow + 16 * k, error);
    }
  }
  EXPECT_EQ(error.find("void"), std::string::npos) << error;
  for (int k = 0; k < Pairings::kCodeTries; ++k)
    p.redeem(wrong_of(code), "10.2.0.1", kOther, kNow + 16 * k, error);
  EXPECT_NE(error.find("now void"), std::string::npos) << error;
  EXPECT_FALSE(p.redeem(code, "10.3.0.1", kTablet, kNow + 100, error));
}

TEST(Pairings, ATokenCountsOnlyFromTheDeviceThatRedeemedIt) {
  Pairings p;
  std::string error;
  const auto paired = p.redeem(p.new_code("tablet", 2, kNow), "10.0.0.5", kTablet, kNow, error);
  ASSERT_TRUE(paired) << error;
  bool elsewhere = true;
  EXPECT_TRUE(p.find(paired->token, "10.0.0.5", kTablet, kNow + 1, &elsewhere));
  EXPECT_FALSE(elsewhere);
  // Captured off the hall network and replayed from another address, even with the secret.
  EXPECT_FALSE(p.find(paired->token, "10.0.0.6", kTablet, kNow + 1, &elsewhere));
  EXPECT_TRUE(elsewhere);
  // From the right address (spoofed, or behind the same NAT) without the page's secret.
  EXPECT_FALSE(p.find(paired->token, "10.0.0.5", "", kNow + 1, &elsewhere));
  EXPECT_TRUE(elsewhere);
  EXPECT_FALSE(p.find(paired->token, "10.0.0.5", kOther, kNow + 1, &elsewhere));
  EXPECT_FALSE(p.find(paired->token, "10.0.0.5", kTablet, kNow + 2 * 3600, &elsewhere));
  EXPECT_FALSE(elsewhere);  // expired: not live anywhere
  // A redeem without a device secret pairs nothing.
  EXPECT_FALSE(p.redeem(p.new_code("tablet", 2, kNow), "10.0.0.5", "", kNow, error));
  EXPECT_NE(error.find("device secret"), std::string::npos) << error;
}
