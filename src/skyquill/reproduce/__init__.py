"""Reproduction harness: peer implementations that skyquill compares itself with."""
