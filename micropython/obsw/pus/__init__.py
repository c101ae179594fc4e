"""PUS-C (ECSS-E-ST-70-41C): packets, field types, services."""
