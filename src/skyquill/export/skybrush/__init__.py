"""Delivery to Skybrush (Live, Studio, the server and its drones): keyframes on Skybrush's grid
(:mod:`.keyframes`), what a drone plays from them (:mod:`.playback`), light programs
(:mod:`.lights`), the ``.skyc`` archive (:mod:`.skyc_file`) and Studio's CSV zip
(:mod:`.csv_file`), their validation settings (:mod:`.validation`) and the two exporters
(:mod:`.skyc_exporter`, :mod:`.csv_exporter`).
"""

#: DEFLATE level of the archives written (``.skyc``, Studio's CSV zip): the fastest. On a
#: 1,000-drone show's 165 kB CSVs it takes a fifth of the default level's (6) time for
#: archives 9 % larger; the members are the same bytes, and any level reads the same.
DEFLATE_LEVEL = 1
