"""PUS on the host: the on-board process on UDP, the ground process and its scripting API."""
