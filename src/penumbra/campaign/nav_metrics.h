#pragma once
// the metrics of a point-goal navigation episode, computed by the benchmark harness from what
// the simulator itself wrote (the base body's ground-truth pose series and the robot's contact
// intervals), never from the method's own report. the metrics follow the URLab paper's
// navigation table (success, collisions, time to goal, goal distance, SC); SC, success
// weighted by collisions, is from Eftekhar et al., "Selective Visual Representations Improve
// Convergence and Generalization for Embodied AI", ICLR 2024: SC = (1/N) sum_i S_i / (1 + c_i)
// over N episodes, S_i in {0, 1} the success and c_i the collision count of episode i.

#include <string>
#include <vector>

namespace penumbra {

/// one sample of the base body's pose X_WB (world frame: m; orientation a unit quaternion).
struct NavPoseSample {
  double time_sec = 0;
  double x = 0, y = 0, z = 0;
  double qw = 1, qx = 0, qy = 0, qz = 0;
};

/// one interval during which a (robot part, other part) pair was in contact, as the run's
/// contacts metric writes them with a debounce of 0 (metrics/collision_counter.h): the pair's
/// summed normal force was >= the threshold at every detection step from start to end.
struct ContactInterval {
  std::string a, b;      ///< the pair's sides (composed body names); (a, b) == (b, a)
  double start_sec = 0;  ///< first instant in contact, s
  double end_sec = 0;    ///< last instant in contact, s (>= start_sec)
  /// at the start: the speed of a's mover towards b's and of b's towards a's (m/s; the
  /// episodes file's a_speed_toward_b_m_s, b_speed_toward_a_m_s; metrics/metrics_sink.h)
  double a_toward_b_m_s = 0, b_toward_a_m_s = 0;
};

/// names the sides of `contacts` as the judge counts them, in place: every part of the robot
/// (a body "<robot>/...") becomes `robot`, every body of an NPC agent (its root "agents/<name>"
/// and its limbs or wheels "agents/<name>/<part>", compose/agent_bodies.h) becomes its root,
/// so that one robot touching one agent is one pair whichever limbs touch.
void NameContactSides(const std::string& robot, std::vector<ContactInterval>* contacts);

/// an agent slower than this towards the robot never makes a contact, m/s (a standing agent
/// touched by a robot that bounces back is still the robot's collision).
inline constexpr double kAgentContactMinSpeed = 0.1;

/// who made a contact of the robot named `robot` (ContactInterval sides already named by the
/// robot, not its parts): an NPC agent (the other side is an agent body, "agents/...", see
/// compose/agent_bodies.h) whose speed towards the robot at the start of the contact is at
/// least kAgentContactMinSpeed and exceeds the robot's speed towards it made the contact
/// (true); any other contact (a wall, a table, a box, an agent the robot drove into, or a pair
/// without the robot) is the robot's (false).
bool AgentMadeContact(const ContactInterval& contact, const std::string& robot);

/// collisions split by who made them (AgentMadeContact).
struct CollisionCounts {
  int robot = 0;  ///< caused by the robot
  int agent = 0;  ///< made by an agent walking or driving into the robot
};

/// CountCollisions with each merged run attributed by its first interval (AgentMadeContact
/// with `robot`; "" = every collision is the robot's). robot + agent = CountCollisions.
/// @throws Error as CountCollisions.
CollisionCounts CountCollisionsByCause(std::vector<ContactInterval> intervals, double debounce_sec,
                                       double until_sec, const std::string& robot);

/// collisions: the intervals of each unordered pair, sorted by start, merged while the next
/// one starts less than `debounce_sec` after the end of the merged one (contact chatter, a
/// bounce or a trot step along a wall are one collision); every merged run is one collision.
/// intervals that start after `until_sec` are ignored (contacts after the episode ended).
/// debounce_sec = 0: every interval counts. @throws Error for debounce_sec < 0 or an interval
/// with end_sec < start_sec.
int CountCollisions(std::vector<ContactInterval> intervals, double debounce_sec, double until_sec);

/// what a navigation episode is judged by.
struct NavEpisodeTask {
  double goal_x = 0, goal_y = 0;  ///< world frame, m
  double radius_m = 0.5;          ///< success radius, m
  double timeout_sec = 60;        ///< sim time, s
  double fall_height_m = 0.15;    ///< a fall: base z below this, m ...
  double max_tilt_deg = 45;       ///< ... or |roll| or |pitch| above this, deg
  double debounce_sec = 0.5;      ///< CountCollisions' window, s
  std::string robot;  ///< the robot's side name in the contacts ("": no agent attribution)
};

/// an episode's metrics.
struct NavEpisodeMetrics {
  bool success = false;    ///< the base origin within radius_m of the goal (horizontal) at the
                           ///< end, no fall, and the method did not fail
  int collisions = 0;      ///< collisions the robot caused up to the end of the episode
                           ///< (CountCollisionsByCause); SC counts these
  int agent_contacts = 0;  ///< contacts an agent made (walked / drove into the robot)
  bool fell = false;
  double fall_time_sec = -1;         ///< first sample that is a fall, s (-1: none)
  double time_to_goal_sec = -1;      ///< first sample within the radius, s; -1 when never (or not a
                                     ///< success)
  double final_goal_distance_m = 0;  ///< horizontal, at the end
  double episode_time_sec = 0;       ///< time of the end sample minus the first sample's
  double path_length_m = 0;          ///< horizontal length of the base's path, m
  double sc = 0;                     ///< S / (1 + c) of this episode
};

/// the metrics of one episode from the base pose series (time-ordered, at least one sample)
/// and the contact intervals. the episode ends at the last sample, at the first fall or at
/// timeout_sec after the first sample, whichever comes first. `method_ok`: false makes the
/// episode a failure (a method that crashed or was killed), its other metrics still computed.
/// @throws Error for an empty or unordered series or a debounce < 0.
NavEpisodeMetrics EvaluateNavEpisode(const std::vector<NavPoseSample>& poses,
                                     const std::vector<ContactInterval>& contacts,
                                     const NavEpisodeTask& task, bool method_ok);

/// SC = mean over episodes of S_i / (1 + c_i) (Eftekhar et al. 2024); NaN for no episodes.
/// `success` and `collisions` have one entry per episode. @throws Error when their sizes
/// differ or a collision count is negative.
double SuccessWeightedByCollisions(const std::vector<bool>& success,
                                   const std::vector<int>& collisions);

}  // namespace penumbra
