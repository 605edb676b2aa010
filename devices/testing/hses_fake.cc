#include "devices/testing/hses_fake.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace tubepick::devices {
namespace {

constexpr std::uint8_t kStatusUndefinedCommand = 0x08;
constexpr std::uint8_t kStatusError = 0x1F;
constexpr std::uint16_t kAddedServoOff = 0x2070;  // "Servo OFF"
constexpr std::uint16_t kAddedBadData = 0xB004;   // "Out of range the data"
constexpr std::uint16_t kAddedUndefinedCommand = 0xA000;

}  // namespace

HsesFake::HsesFake(std::chrono::milliseconds move_duration)
    : move_duration_(move_duration),
      server_("HsesFake", [this](std::span<const std::uint8_t> d) { return Serve(d); }) {}

void HsesFake::SetErrorStatus(std::uint8_t status, std::uint16_t added_status) {
  std::lock_guard lock(mutex_);
  error_status_ = status;
  error_added_ = added_status;
}

void HsesFake::SetSilent(bool silent) {
  std::lock_guard lock(mutex_);
  silent_ = silent;
}

void HsesFake::SetPosition(const std::array<std::int32_t, 6>& words) {
  std::lock_guard lock(mutex_);
  position_ = words;
}

std::array<std::int32_t, 6> HsesFake::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

bool HsesFake::servo_on() const {
  std::lock_guard lock(mutex_);
  return servo_on_;
}

int HsesFake::status_reads() const {
  std::lock_guard lock(mutex_);
  return status_reads_;
}

std::vector<hses::Request> HsesFake::requests() const {
  std::lock_guard lock(mutex_);
  return requests_;
}

std::vector<std::array<std::int32_t, hses::kMoveWords>> HsesFake::moves() const {
  std::lock_guard lock(mutex_);
  return moves_;
}

// Called with mutex_ held.
hses::Answer HsesFake::Handle(const hses::Request& request) {
  hses::Answer answer;
  answer.request_id = request.request_id;
  answer.service = static_cast<std::uint8_t>(request.service | 0x80);
  const auto fail = [&answer](std::uint8_t status, std::uint16_t added) {
    answer.status = status;
    answer.added_status_size = added != 0 ? 1 : 0;
    answer.added_status = added;
    answer.data.clear();
    return answer;
  };
  if (error_status_ != 0) {
    return fail(error_status_, error_added_);
  }
  if (moving_ && std::chrono::steady_clock::now() >= move_end_) {
    moving_ = false;
    position_ = target_;
  }
  const std::vector<std::int32_t> words = hses::DecodeWords(request.data);
  switch (static_cast<hses::Command>(request.command)) {
    case hses::Command::kStatusRead: {
      ++status_reads_;
      const std::int32_t data[2] = {static_cast<std::int32_t>(moving_ ? hses::kStatus1Running : 0u),
                                    static_cast<std::int32_t>(servo_on_ ? hses::kStatus2ServoOn : 0u)};
      answer.data = hses::EncodeWords(data);
      return answer;
    }
    case hses::Command::kPositionRead: {
      if (request.instance != hses::kBasePositionInstance) {
        return fail(kStatusError, kAddedBadData);
      }
      std::array<std::int32_t, hses::kPositionWords> data{};
      data[0] = hses::kCoordinateBase;
      std::copy(position_.begin(), position_.end(), data.begin() + 5);
      answer.data = hses::EncodeWords(data);
      return answer;
    }
    case hses::Command::kHoldServo: {
      if (request.instance != hses::kServoInstance || words.size() != 1 ||
          (words[0] != hses::kOn && words[0] != hses::kOff)) {
        return fail(kStatusError, kAddedBadData);
      }
      servo_on_ = words[0] == hses::kOn;
      return answer;
    }
    case hses::Command::kMoveCartesian: {
      if (words.size() != hses::kMoveWords || request.instance != hses::kStraightAbsolute) {
        return fail(kStatusError, kAddedBadData);
      }
      std::array<std::int32_t, hses::kMoveWords> move{};
      std::copy(words.begin(), words.end(), move.begin());
      moves_.push_back(move);
      if (!servo_on_) {
        return fail(kStatusError, kAddedServoOff);
      }
      std::copy(move.begin() + 5, move.begin() + 11, target_.begin());
      moving_ = true;
      move_end_ = std::chrono::steady_clock::now() + move_duration_;
      return answer;
    }
  }
  return fail(kStatusUndefinedCommand, kAddedUndefinedCommand);
}

std::vector<LoopbackUdpServer::Datagram> HsesFake::Serve(std::span<const std::uint8_t> datagram) {
  const auto request = hses::DecodeRequest(datagram);
  if (!request) {
    return {};
  }
  std::lock_guard lock(mutex_);
  requests_.push_back(*request);
  if (silent_) {
    return {};
  }
  return {hses::EncodeAnswer(Handle(*request))};
}

}  // namespace tubepick::devices
