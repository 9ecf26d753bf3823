// The LCM channels of a run, defined once. See lcmtypes/README.md for who publishes what.
#pragma once

namespace rl::channels {

// Main port (small and high-rate messages).
inline constexpr char kTransitions[] = "RL_TRANSITIONS";         // transition_batch_t, actors
inline constexpr char kPriorities[] = "RL_PRIORITIES";           // priority_update_t, learner
inline constexpr char kSampleRequest[] = "RL_SAMPLE_REQUEST";    // sample_request_t, learner
inline constexpr char kFlow[] = "RL_FLOW";                       // flow_control_t, replay
inline constexpr char kCheckpoint[] = "RL_CHECKPOINT";           // checkpoint_t, learner
inline constexpr char kEval[] = "RL_EVAL";                       // eval_result_t, evaluator
inline constexpr char kStatsActor[] = "RL_STATS_ACTOR";          // stats_actor_t
inline constexpr char kStatsReplay[] = "RL_STATS_REPLAY";        // stats_replay_t
inline constexpr char kStatsLearner[] = "RL_STATS_LEARNER";      // stats_learner_t
inline constexpr char kStatsEvaluator[] = "RL_STATS_EVALUATOR";  // stats_evaluator_t

// Bulk port (large messages).
inline constexpr char kSamples[] = "RL_SAMPLES";  // sample_batch_t, replay
inline constexpr char kWeights[] = "RL_WEIGHTS";  // weights_chunk_t, learner

}  // namespace rl::channels
