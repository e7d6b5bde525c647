"""Delivery to PX4: offboard setpoints in NED and their MAVSDK streamer (:mod:`.setpoints`),
the local NED CSV (:mod:`.local_exporter`) and the geographic mission (:mod:`.global_exporter`).
"""
