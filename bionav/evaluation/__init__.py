"""Evaluation of homing methods: quality measures, the return agent, all-pairs runs."""
