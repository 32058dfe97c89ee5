# Sourced by the case tests that read particle files by hand (an independent reading: h5dump,
# not lubkit's reader).
#
#     h5vals FILE DATASET     the dataset's values in file order, one per line, at full
#                             precision (position, velocity: x y z of each particle in turn)
h5vals() {
    h5dump -y -w 0 -m %.17g -d "$2" "$1" |
        awk '/DATA \{/ { on = 1; next } on && /^ *\}/ { on = 0 } on { gsub(/,/, " "); for (i = 1; i <= NF; i++) print $i }'
}
