#!/usr/bin/env bash
# Fetches recordings of real people from Debian packages and labels them, for training and
# evaluating the front end (the speakers and their train/networks/dev/tune split:
# config/corpus/real-speakers.txt).
#
#   scripts/fetch-real-speech.sh OUT_DIR                # every speaker: OUT_DIR/SPLIT/SPEAKER/
#   scripts/fetch-real-speech.sh OUT_DIR --subset 8     # the first 8 files of each speaker
#   scripts/fetch-real-speech.sh OUT_DIR --split dev    # only the dev speakers
#   scripts/fetch-real-speech.sh OUT_DIR --split tune   # only the voices held out for decisions
#   scripts/fetch-real-speech.sh OUT_DIR --split networks  # only the networks' extra speakers
#
# Packages are fetched with `apt-get download` and unpacked with `dpkg -x` into a cache
# ($REAL_SPEECH_CACHE, default build/real-speech-cache): no root needed, nothing installed, and
# the audio never enters the repository. Labelling needs sox and, for the English word lists,
# pocketsphinx + pocketsphinx-en-us (a development-time labeller; the product never uses it):
# `apt-get install sox libsox-fmt-base pocketsphinx pocketsphinx-en-us` (and libsox-fmt-mp3 for
# the fotaq source, ffmpeg for the asterisk sources: their prompts are labelled on the 16 kHz
# G.722 recordings, pocketsphinx's model being a 16 kHz one, and trained on the 8 kHz WAVs).
# Exit codes: 0 done, 1 error, 2 usage, 77 the packages or tools cannot be had (tests skip).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: fetch-real-speech.sh OUT_DIR [--subset N] [--split train|networks|dev|tune]}"
shift
cache="${REAL_SPEECH_CACHE:-$here/build/real-speech-cache}"

split="" mp3="" g722=""
for ((i = 1; i <= $#; i++)); do [ "${!i}" = --split ] && { j=$((i + 1)); split="${!j:-}"; }; done

# The packages behind the speakers asked for (config/corpus/real-speakers.txt: SOURCE column).
packages=()
while read -r speaker kind source; do
  case "$speaker" in ''|'#'*) continue ;; esac
  [ -n "$split" ] && [ "$kind" != "$split" ] && continue
  case "$source" in
    asterisk:*) lang="${source##*:}" g722=1  # the 16 kHz G.722 recordings are what is labelled
                packages+=("asterisk-core-sounds-$lang-wav" "asterisk-core-sounds-$lang-g722"
                           "asterisk-core-sounds-$lang") ;;
    klettres:*) packages+=(klettres-data) ;;
    ktuberling:*) packages+=(ktuberling-data) ;;
    fillets:*) lang="${source#fillets:}" lang="${lang%%:*}"
               packages+=(fillets-ng-data "fillets-ng-data-$lang") ;;
    festvox-ru) packages+=(festvox-ru) ;;
    tuxpaint:*) packages+=(tuxpaint-stamps-default) ;;
    fotaq) packages+=(flight-of-the-amazon-queen) mp3=1 ;;
    *) echo "fetch-real-speech.sh: $speaker: unknown source '$source'" >&2; exit 1 ;;
  esac
done <"$here/config/corpus/real-speakers.txt"
mapfile -t packages < <(printf '%s\n' "${packages[@]}" | sort -u)
tools=(sox soxi pocketsphinx_continuous python3)

unavailable() { echo "fetch-real-speech.sh: $*" >&2; exit 77; }

for t in "${tools[@]}"; do
  command -v "$t" >/dev/null ||
    unavailable "$t not found (apt-get install sox libsox-fmt-base pocketsphinx pocketsphinx-en-us)"
done
[ -z "$mp3" ] || sox -h 2>/dev/null | grep -q 'FORMATS:.* mp3' ||
  unavailable "sox cannot read MP3 (apt-get install libsox-fmt-mp3), needed by the fotaq source"
[ -z "$g722" ] || command -v ffmpeg >/dev/null ||
  unavailable "ffmpeg not found (apt-get install ffmpeg), needed to decode the asterisk prompts' G.722 recordings"
[ -f /usr/share/pocketsphinx/model/en-us/cmudict-en-us.dict ] ||
  unavailable "the pocketsphinx-en-us model is not installed (apt-get install pocketsphinx-en-us)"

[ ${#packages[@]} -eq 0 ] || "$here/scripts/fetch-packages.sh" "$cache" "${packages[@]}"

python3 "$here/scripts/label-real-speech.py" "$cache/root" "$out" "$@"
