"""Delivery to Skybrush (Live, Studio, the server and its drones): keyframes on Skybrush's grid
(:mod:`.keyframes`), what a drone plays from them (:mod:`.playback`), light programs
(:mod:`.lights`), the ``.skyc`` archive (:mod:`.skyc_file`) and Studio's CSV zip
(:mod:`.csv_file`), their validation settings (:mod:`.validation`) and the two exporters
(:mod:`.skyc_exporter`, :mod:`.csv_exporter`).
"""
