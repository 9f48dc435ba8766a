"""The arena as reinforcement-learning environments: every robot an agent of a PettingZoo
ParallelEnv (`parallel_env`), or one robot a Gymnasium env (`make`), over the same world and
tick as the in-process engine (docs/envs.md)."""

from swarm.envs.parallel import ArenaParallelEnv, parallel_env
from swarm.envs.single import ArenaGymEnv, make

__all__ = ["ArenaGymEnv", "ArenaParallelEnv", "make", "parallel_env"]
