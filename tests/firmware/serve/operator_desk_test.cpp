// The control socket's decisions (issue 22): every command in every loom state, from each kind of
// station — a local socket user, an unpaired panel client, a paired one — answers `ok` (and hands the
// command to the loop) only when it changes something and the station may give it; else `refused: why`.
// The expected table is written out here by hand from the rules (operator_desk.hpp), not computed.
#include "loom/firmware/serve/operator_desk.hpp"

#include <gtest/gtest.h>

#include <map>
#include <string>

using namespace loom;
using namespace loom::firmware::serve;
using sequencer::State;

namespace {

constexpr std::int64_t kNow = 1'800'000'000;
constexpr const char* kDevice = "00112233445566778899aabbccddeeff";  // the page's per-device secret

struct Row {
  State state;
  const char* name;
  // Which of start pause resume stop ack next change something here (knotting recipe, chain closed).
  const char* ok;
};

// By hand: start from idle or done; pause while weaving; resume while paused; stop while weaving or
// paused; ack only in a fault; next only while waiting for the weaver; nothing but ack in a fault.
const Row kTable[] = {
    {State::kIdle, "idle", "start"},
    {State::kEnabling, "enabling", "pause stop"},
    {State::kHoming, "homing", "pause stop"},
    {State::kPositioning, "positioning", "pause stop"},
    {State::kShedTest, "shed_test", "pause stop"},
    {State::kShed, "shed", "pause stop"},
    {State::kPick, "pick", "pause stop"},
    {State::kBeatSweep, "beat_sweep", "pause stop"},
    {State::kRowEnd, "row_end", "pause stop"},
    {State::kAwaitKnotting, "await_knotting", "pause stop next"},
    {State::kKnotting, "knotting", "pause stop"},  // next only while the heads ask the weaver (below)
    {State::kPaused, "paused", "resume stop"},
    {State::kDone, "done", "start"},
    {State::kFault, "fault", "ack"},
};
const char* const kCommands[] = {"start", "pause", "resume", "stop", "ack", "next"};

bool listed(const std::string& list, const std::string& w) {
  return (" " + list + " ").find(" " + w + " ") != std::string::npos;
}

LoomView view(State s) {
  LoomView v;
  v.state = s;
  v.fault = s == State::kFault ? sequencer::Fault::kDriveFault : sequencer::Fault::kNone;
  v.knotting = true;
  return v;
}

ControlRequest local(const std::string& line) {
  return {line, Peer{4242, 1000, 1000, "anna"}};
}

}  // namespace

TEST(OperatorDesk, EveryCommandInEveryStateFromEveryStationIsTrue) {
  Pairings pairings;
  OperatorDesk desk(pairings, "can0");
  std::string error;
  const std::string token =
      pairings.redeem(pairings.new_code("tab1", 1, kNow), "10.0.0.7", kDevice, kNow, error)->token;
  for (const Row& row : kTable) {
    for (const char* cmd : kCommands) {
      const bool starting = std::string(cmd) != "pause" && std::string(cmd) != "stop";
      const bool changes = listed(row.ok, cmd);
      struct Station {
        std::string suffix;
        bool may;
      } stations[] = {
          {"", true},
          {" via=panel client=10.0.0.7", !starting},
          {" via=panel client=10.0.0.7 device=" + std::string(kDevice) + " token=" + token, true},
          {" via=panel client=10.0.0.7 token=00000000000000000000000000000000", !starting},
          // The token replayed from another address, or without the device's secret.
          {" via=panel client=10.0.0.8 device=" + std::string(kDevice) + " token=" + token, !starting},
          {" via=panel client=10.0.0.7 token=" + token, !starting}};
      for (const Station& st : stations) {
        SCOPED_TRACE(std::string(row.name) + ": " + cmd + st.suffix);
        const Decision d = desk.decide(local(cmd + st.suffix), view(row.state), kNow);
        const bool ok = changes && st.may;
        EXPECT_EQ(d.accepted(), ok) << d.reply;
        EXPECT_EQ(d.post.has_value(), ok) << d.reply;
        EXPECT_TRUE(d.audit);
        if (!ok) {
          EXPECT_EQ(d.reply.rfind(std::string("refused: ") + cmd + ": ", 0), 0u) << d.reply;
        }
        if (!st.may) {
          EXPECT_NE(d.reply.find("paired panel client"), std::string::npos) << d.reply;
        }
      }
    }
  }
}

TEST(OperatorDesk, RefusalsSayWhy) {
  Pairings pairings;
  OperatorDesk desk(pairings, "can1");
  LoomView fault = view(State::kFault);
  fault.estop_ok = false;
  EXPECT_EQ(
      desk.decide(local("ack"), fault, kNow).reply,
      "refused: ack: the e-stop chain is still open: close it (release the e-stop), then acknowledge\n");
  fault.estop_ok = true;
  fault.recovery = hal::LinkRecovery::kNodeSilent;
  fault.silent_node = 3;
  EXPECT_NE(desk.decide(local("ack"), fault, kNow).reply.find("node 3 is still silent"), std::string::npos);
  fault.recovery = hal::LinkRecovery::kBusOff;
  EXPECT_NE(desk.decide(local("ack"), fault, kNow).reply.find("ip link set can1"), std::string::npos);
  EXPECT_EQ(desk.decide(local("start"), fault, kNow).reply,
            "refused: start: drive_fault is latched: acknowledge it first (ctl ack)\n");
  EXPECT_EQ(desk.decide(local("ack"), view(State::kPick), kNow).reply,
            "refused: ack: no fault is latched (state pick)\n");
  // The counters woven are not yet on disk (full disk): an ack would re-arm from the file's older counts,
  // so the loop refuses it; the reply must say so, not `ok ack` (issue 22, item 6).
  LoomView unsaved = view(State::kFault);
  unsaved.fault = sequencer::Fault::kCountersNotSaved;
  unsaved.counters_unsaved = true;
  const Decision ack_unsaved = desk.decide(local("ack"), unsaved, kNow);
  EXPECT_EQ(
      ack_unsaved.reply,
      "refused: ack: the counters woven are not on disk yet (the last save failed): free space in the state "
      "directory; the save is retried every second, then acknowledge\n");
  EXPECT_FALSE(ack_unsaved.post.has_value());
  EXPECT_TRUE(ack_unsaved.audit);
  unsaved.counters_unsaved = false;  // the retried save went through
  EXPECT_EQ(desk.decide(local("ack"), unsaved, kNow).reply, "ok ack\n");
  LoomView idle = view(State::kIdle);
  idle.estop_ok = false;
  EXPECT_EQ(desk.decide(local("start"), idle, kNow).reply,
            "refused: start: the e-stop chain is open: close it first\n");
  LoomView plain = view(State::kAwaitKnotting);
  plain.knotting = false;
  EXPECT_NE(desk.decide(local("next"), plain, kNow).reply.find("no weaver's knotting"), std::string::npos);
  // The knotting heads asking the weaver (a knot to tie by hand, a slot to reload): next answers them.
  LoomView heads = view(State::kKnotting);
  heads.knotting = false;
  EXPECT_NE(desk.decide(local("next"), heads, kNow).reply.find("not waiting for the weaver"),
            std::string::npos);
  heads.weaver_ask = sequencer::WeaverAsk::kTieByHand;
  EXPECT_EQ(desk.decide(local("next"), heads, kNow).reply.rfind("refused", 0), std::string::npos)
      << desk.decide(local("next"), heads, kNow).reply;
  EXPECT_EQ(desk.decide(local("dance"), idle, kNow).reply.rfind("error: unknown command 'dance'", 0), 0u);
  EXPECT_EQ(desk.decide(local("start now"), idle, kNow).reply,
            "error: start takes no argument (got 'now')\n");
  EXPECT_EQ(desk.decide(local("start hours=3"), idle, kNow).reply, "error: hours= is for pair only\n");
  EXPECT_EQ(desk.decide(local("start via=lan client=x"), idle, kNow).reply,
            "error: via=lan: only via=panel\n");
  EXPECT_EQ(desk.decide(local("start via=panel"), idle, kNow).reply, "error: via=panel needs client=ADDR\n");
  EXPECT_EQ(desk.decide(local(std::string("start\x01")), idle, kNow)
                .reply.rfind("error: request has a character", 0),
            0u);
}

TEST(OperatorDesk, WhoGaveTheCommandIsTheKernelsWordAndThePanelsClient) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  EXPECT_EQ(desk.decide(local("pause"), view(State::kPick), kNow).who,
            "local user anna (uid 1000, pid 4242)");
  EXPECT_EQ(desk.decide(local("pause via=panel client=10.0.0.7"), view(State::kPick), kNow).who,
            "panel client 10.0.0.7 (not paired) via local user anna (uid 1000, pid 4242)");
  // The COMMAND event's station.
  EXPECT_EQ(desk.decide(local("pause"), view(State::kPick), kNow).station, "local");
  EXPECT_EQ(desk.decide(local("pause via=panel client=10.0.0.7"), view(State::kPick), kNow).station, "panel");
}

// The I/O module's buttons go to the loop directly; their audit carries what the same command from the
// socket would have answered in the state of the press.
TEST(OperatorDesk, AButtonPressIsAnsweredAsTheSameCommandWouldBe) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  EXPECT_EQ(desk.answer_in_state("start", view(State::kIdle)), "ok start");
  EXPECT_EQ(desk.answer_in_state("start", view(State::kPick)),
            "refused: start: already weaving (state pick)");
  EXPECT_EQ(desk.answer_in_state("pause", view(State::kPick)), "ok pause");
  EXPECT_EQ(desk.answer_in_state("ack", view(State::kPick)),
            "refused: ack: no fault is latched (state pick)");
  LoomView open = view(State::kFault);
  open.estop_ok = false;
  EXPECT_EQ(desk.answer_in_state("ack", open),
            "refused: ack: the e-stop chain is still open: close it (release the e-stop), then acknowledge");
  EXPECT_EQ(desk.answer_in_state("ack", view(State::kFault)), "ok ack");
}

TEST(OperatorDesk, PairingIsDoneAtTheLoomCodesExpireAndTokensAreRevocable) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  const LoomView paused = view(State::kPaused);
  // Never through a panel: a panel client cannot pair itself or others.
  EXPECT_EQ(
      desk.decide(local("pair x via=panel client=1.2.3.4"), paused, kNow).reply.rfind("refused: pair:", 0),
      0u);
  const std::string reply = desk.decide(local("pair tab2 hours=2"), paused, kNow).reply;
  ASSERT_EQ(reply.rfind("ok pair tab2 code=", 0), 0u) << reply;
  const std::string code = reply.substr(18, 6);
  const std::string redeem = "redeem via=panel client=1.2.3.4 device=" + std::string(kDevice) + " code=";
  // Wrong tries from this address: each followed by a wait, five in all, then this device is out.
  EXPECT_NE(desk.decide(local(redeem + "x"), paused, kNow).reply.find("4 tries left from this device"),
            std::string::npos);
  EXPECT_NE(desk.decide(local(redeem + code), paused, kNow).reply.find("wait 1 s"), std::string::npos);
  for (int i = 1; i < Pairings::kCodeTries; ++i) {
    EXPECT_EQ(desk.decide(local(redeem + "x"), paused, kNow + 20 * i)
                  .reply.rfind("refused: redeem: wrong pairing code", 0),
              0u);
  }
  EXPECT_NE(
      desk.decide(local(redeem + code), paused, kNow + 100).reply.find("wrong codes: ask for a new code"),
      std::string::npos);
  // Without the page's device secret nothing is redeemed.
  EXPECT_NE(desk.decide(local("redeem via=panel client=1.2.3.4 code=" + code), paused, kNow)
                .reply.find("device secret"),
            std::string::npos);
  // A fresh code, redeemed in time: a token valid 2 h.
  const std::string code2 = desk.decide(local("pair tab2 hours=2"), paused, kNow).reply.substr(18, 6);
  EXPECT_NE(desk.decide(local(redeem + code2), paused, kNow + Pairings::kCodeLifetimeS).reply.find("expired"),
            std::string::npos);
  EXPECT_NE(desk.decide(local(redeem + code2), paused, kNow).reply.find("no pairing code"),
            std::string::npos);
  const std::string code3 = desk.decide(local("pair tab2 hours=2"), paused, kNow).reply.substr(18, 6);
  const std::string ok = desk.decide(local(redeem + code3), paused, kNow + 10).reply;
  ASSERT_EQ(ok.rfind("ok redeem tab2 token=", 0), 0u) << ok;
  // The cookie's Max-Age: what is left of the pairing.
  EXPECT_NE(ok.find(" valid_s=7200\n"), std::string::npos) << ok;
  const std::string token = ok.substr(21, 32);
  const std::string resume =
      "resume via=panel client=1.2.3.4 device=" + std::string(kDevice) + " token=" + token;
  EXPECT_TRUE(desk.decide(local(resume), paused, kNow + 7199).accepted());
  EXPECT_FALSE(desk.decide(local(resume), paused, kNow + 7210).accepted());  // expired after 2 h
  EXPECT_TRUE(desk.decide(local(resume), paused, kNow + 100).accepted());
  EXPECT_EQ(desk.decide(local("unpair tab2"), paused, kNow).reply, "ok unpair tab2 (1 revoked)\n");
  EXPECT_FALSE(desk.decide(local(resume), paused, kNow + 100).accepted());
  EXPECT_EQ(desk.decide(local("unpair tab2"), paused, kNow).reply.rfind("refused:", 0), 0u);
}

// A pause given but not reached yet (the heads are tying; the loom holds before the next shed): resume
// withdraws it (issue 30: it answered "not paused"). Without a pending pause resume is refused as before.
TEST(OperatorDesk, ResumeWithdrawsAPauseNotReachedYet) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  LoomView v = view(State::kKnotting);
  EXPECT_EQ(desk.decide(local("resume"), v, kNow).reply, "refused: resume: not paused (state knotting)\n");
  v.pause_pending = true;
  const Decision d = desk.decide(local("resume"), v, kNow);
  EXPECT_EQ(d.reply, "ok resume\n");
  ASSERT_TRUE(d.post.has_value());
  EXPECT_EQ(*d.post, firmware::Command::kResume);
  // Still a starting command: not from an unpaired panel client.
  EXPECT_FALSE(desk.decide(local("resume via=panel client=10.0.0.7"), v, kNow).accepted());
  // Nothing to withdraw once the loom no longer weaves.
  v.state = State::kDone;
  EXPECT_FALSE(desk.decide(local("resume"), v, kNow).accepted());
}

// `reload head=H slot=S [knots=K]` (ctl reload HEAD SLOT [KNOTS]): the weaver put yarn in a magazine slot.
// Accepted in every state (a fault too: the yarn is there), from a local user or a paired panel client only
// (it answers the heads' request to reload that slot, and they go on); checked against the loom's heads,
// slots and slot size; handed to the loop with the numbers 0-based.
TEST(OperatorDesk, AReloadIsAFactInEveryStateFromAStationThatSeesTheLoom) {
  Pairings pairings;
  OperatorDesk desk(pairings, "can0");
  const auto with_heads = [](State s) {
    LoomView v = view(s);
    v.heads = 3;
    v.slots = 4;
    v.knots_per_slot = 150;
    return v;
  };
  for (const Row& row : kTable) {
    SCOPED_TRACE(row.name);
    const Decision d = desk.decide(local("reload head=2 slot=3 knots=40"), with_heads(row.state), kNow);
    EXPECT_TRUE(d.accepted()) << d.reply;
    ASSERT_TRUE(d.post.has_value());
    EXPECT_EQ(*d.post, firmware::Command::kReload);
    ASSERT_TRUE(d.reload.has_value());
    EXPECT_EQ(d.reload->head, 1);
    EXPECT_EQ(d.reload->slot, 3);
    EXPECT_EQ(d.reload->knots, 40);
    EXPECT_TRUE(d.audit);
  }
  const LoomView v = with_heads(State::kKnotting);
  const Decision full = desk.decide(local("reload head=1 slot=0"), v, kNow);
  ASSERT_TRUE(full.reload.has_value());
  EXPECT_EQ(full.reload->knots, -1);  // full
  const Decision unpaired = desk.decide(local("reload head=1 slot=0 via=panel client=10.0.0.7"), v, kNow);
  EXPECT_FALSE(unpaired.post.has_value());
  EXPECT_NE(unpaired.reply.find("paired panel client"), std::string::npos) << unpaired.reply;
  EXPECT_EQ(desk.decide(local("reload head=4 slot=0"), v, kNow).reply,
            "refused: reload: head=4: this loom has heads 1 to 3\n");
  EXPECT_EQ(desk.decide(local("reload head=1 slot=4"), v, kNow).reply,
            "refused: reload: slot=4: the magazines have slots 0 to 3\n");
  EXPECT_EQ(desk.decide(local("reload head=1 slot=0 knots=151"), v, kNow).reply,
            "refused: reload: knots=151: a slot holds at most 150 knots (knotting.knots_per_slot)\n");
  EXPECT_NE(desk.decide(local("reload head=1 slot=0"), view(State::kKnotting), kNow)
                .reply.find("no knotting heads"),
            std::string::npos);
  EXPECT_EQ(desk.decide(local("reload head=1"), v, kNow).reply,
            "error: reload needs head=H slot=S (e.g. reload head=2 slot=1; knots=K when not full)\n");
  EXPECT_EQ(desk.decide(local("reload head=0 slot=1"), v, kNow).reply,
            "error: head=0: a head number from 1 (as the request names it)\n");
  EXPECT_EQ(desk.decide(local("reload head=1 slot=-1"), v, kNow).reply,
            "error: slot=-1: a slot number from 0 (as the request names it)\n");
  EXPECT_EQ(desk.decide(local("reload head=1 slot=1 knots=9999999"), v, kNow).reply,
            "error: knots=9999999: the knots now in the slot, 0 to 1000000\n");
  EXPECT_EQ(desk.decide(local("start slot=1"), v, kNow).reply, "error: slot= is for reload only\n");
}

// `job VERB` (ctl job ..., the panel's job buttons): list and show are reading, from anyone; add, remove
// and start-over change what the loom weaves next, so they come only from a local user or a paired panel
// client, and are audited. The service carries them out (Read::kJob, the request as parsed); the desk never
// posts a command for them: a job is started by `start`.
TEST(OperatorDesk, JobVerbsReadFromAnyoneAndChangeTheQueueOnlyFromAStationThatSeesTheLoom) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  const std::string unpaired = " via=panel client=10.0.0.7";
  for (const Row& row : kTable) {
    SCOPED_TRACE(row.name);
    for (const std::string line : {"job list", "job show id=3"}) {
      for (const std::string& from : {std::string(), unpaired}) {
        const Decision d = desk.decide(local(line + from), view(row.state), kNow);
        EXPECT_EQ(d.read, Decision::Read::kJob) << line + from << ": " << d.reply;
        EXPECT_FALSE(d.post.has_value());
        EXPECT_FALSE(d.audit);
      }
    }
    for (const std::string line :
         {"job add design=/srv/designs/rug.csv rows=40", "job remove id=2", "job start-over id=2"}) {
      const Decision d = desk.decide(local(line), view(row.state), kNow);
      EXPECT_EQ(d.read, Decision::Read::kJob) << line;
      ASSERT_TRUE(d.request.has_value());
      EXPECT_EQ(d.request->cls, CommandClass::kQueue);
      EXPECT_FALSE(d.post.has_value());
      EXPECT_TRUE(d.audit);
      const Decision panel = desk.decide(local(line + unpaired), view(row.state), kNow);
      EXPECT_EQ(panel.read, Decision::Read::kNone) << line;
      EXPECT_FALSE(panel.post.has_value());
      EXPECT_TRUE(panel.audit);  // a refused change is audited too
      EXPECT_EQ(panel.reply.rfind("refused: job " + line.substr(4, line.find(' ', 4) - 4) + ": ", 0), 0u)
          << panel.reply;
      EXPECT_NE(panel.reply.find("needs a paired panel client (this one is not paired"), std::string::npos)
          << panel.reply;
    }
  }
}

// The request's shape is checked before anything is carried out; each refusal names the field and value.
TEST(OperatorDesk, AJobRequestOfTheWrongShapeIsAnErrorNamingIt) {
  Pairings pairings;
  OperatorDesk desk(pairings, "");
  const std::map<std::string, std::string> errors = {
      {"job", "job needs a verb (list, show, add, remove, start-over)"},
      {"job weave", "job weave: not a verb (list, show, add, remove, start-over)"},
      {"job show", "job show needs id=N (the job's number, as job list shows it)"},
      {"job list id=2", "id= is not for job list"},
      {"job remove id=0", "id=0: not a job number (1, 2, ...)"},
      {"job remove id=x1", "id=x1: not a job number (1, 2, ...)"},
      {"job remove id=99999999999", "id=99999999999: not a job number (1, 2, ...)"},
      {"job add", "job add needs design=PATH (the design file, an absolute path)"},
      {"job add design=rug.csv", "design=rug.csv: an absolute path (the loom's service resolves nothing)"},
      {"job show id=1 design=/a.csv", "design= is for job add only"},
      {"job add design=/a.csv rows=2 repeat=3", "one of rows=, metres=, repeat= (the carpet's length)"},
      {"job add design=/a.csv rows=0", "rows=0: the carpet's rows, 1 to 4294967295"},
      {"job add design=/a.csv repeat=1000001", "repeat=1000001: the design's repeats, 1 to 1000000"},
      {"job add design=/a.csv metres=-1",
       "metres=-1: the carpet's length in metres, a decimal number above 0 "
       "and at most 1000000"},
      {"job add design=/a.csv metres=1e3",
       "metres=1e3: the carpet's length in metres, a decimal number above "
       "0 and at most 1000000"},
      {"job remove id=2 rows=3", "rows=, metres= and repeat= are for job add only"},
      {"start id=2", "id= is for job only"},
      {"status rows=2", "rows= is for job only"},
  };
  for (const auto& [line, why] : errors) {
    const Decision d = desk.decide(local(line), view(State::kIdle), kNow);
    EXPECT_EQ(d.reply, "error: " + why + "\n") << line;
    EXPECT_EQ(d.read, Decision::Read::kNone) << line;
    EXPECT_FALSE(d.audit) << line;
  }
  // A design's path may be longer than any other word (up to the request's 512 bytes).
  const std::string deep = "/srv/" + std::string(300, 'd') + "/rug.csv";
  EXPECT_EQ(desk.decide(local("job add design=" + deep), view(State::kIdle), kNow).request->field("design"),
            deep);
  EXPECT_EQ(desk.decide(local("job add design=/a.csv metres=1.25"), view(State::kIdle), kNow).read,
            Decision::Read::kJob);
}
