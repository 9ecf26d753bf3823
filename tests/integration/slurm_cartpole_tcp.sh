#!/usr/bin/env bash
# slurm_cartpole.sh through LCM's TCP hub on the job's first node (--transport tcp).
exec bash "$(dirname "$0")/slurm_cartpole.sh" tcp
