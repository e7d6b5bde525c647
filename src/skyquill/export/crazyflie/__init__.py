"""Delivery to a Crazyflie (cflib, Crazyswarm2): the trajectory memory as the firmware holds
it (:mod:`.memory`), the polynomial CSV (:mod:`.csv_file`), the exporter that writes and
checks both (:mod:`.exporter`) and the cflib fly script it writes beside them
(:mod:`.fly_script`).
"""
