#!/usr/bin/env bash
# slurm_cartpole.sh through LCM's TCP hub on the job's first node (--transport tcp). Each round
# trip through the hub is slow (README, On a cluster): the learner keeps 16 sample requests in
# flight instead of the preset's 4.
exec bash "$(dirname "$0")/slurm_cartpole.sh" tcp --learner-args "--requests-in-flight 16"
