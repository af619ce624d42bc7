# tube74 — build, run, test, benchmark.
#
#   make          build ./tube74 (and build/libtube74.a it is made from)
#   make run      build, then render the built-in demo scene (the Fig. 10 street) to street.png
#   make test     build and run every test (unit, hard cases, OSMesa cross-check, invariance)
#   make asan     the same test suite under AddressSanitizer + UndefinedBehaviorSanitizer
#   make bench    measured figures (host time, hitac10_seconds, growth 10..10,000 faces)
#   make docs     rewrite the figure tables of README.md and docs/*.md from a run
#   make fuzz     every libFuzzer target (tools/fuzz.sh) for FUZZ_SECONDS each, one at a time
#   make install  ./tube74 to $(DESTDIR)$(PREFIX)/bin and the man page tube74.1 to
#                 $(DESTDIR)$(PREFIX)/share/man/man1 (PREFIX defaults to /usr/local);
#                 make uninstall removes them
#
# Missing Debian packages are installed when run as root, else the exact apt-get line
# is printed (see tools/deps.sh).

CC      ?= cc
PREFIX  ?= /usr/local
DESTDIR ?=
BUILD   ?= build
PROG    ?= tube74
OPT     ?= -O3 -g
CFLAGS  ?= $(OPT)
# -ffp-contract=off: the float filters' proofs (effects/smooth.c, effects/shadow.c, render/points.c)
# count each product's rounding; a fused multiply-add (clang's default where the target has FMA,
# e.g. OPT="-O3 -march=haswell") would change the values they bound. gcc -std=c11 never fuses.
WARN    := -std=c11 -ffp-contract=off -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wmissing-prototypes
CPPFLAGS += -D_POSIX_C_SOURCE=200809L -I.

PKGS     := libpng libusb-1.0 sdl2
# linked: libpng alone. SDL2 (play's window), libusb-1.0 (stream to a USB device, devices)
# and giflib (play --movie) are opened with dlopen by the code that uses them
# (display/dynlib.h), their headers still used: a render loads none of them
LINKPKGS := libpng
# giflib (libgif-dev) has no pkg-config file; test_movie reads the GIFs back with it
TESTNOPCLIBS := -lgif
TESTPKGS := cmocka osmesa glu umockdev-1.0 gio-2.0

LIBDIRS := emu render effects patterns display display/usb
LIBSRC  := $(foreach d,$(LIBDIRS),$(wildcard $(d)/*.c))
LIBOBJ  := $(LIBSRC:%.c=$(BUILD)/%.o)
LIB     := $(BUILD)/libtube74.a
CLISRC  := $(wildcard cli/*.c)
# the teaching page (cli/teach_page.html) is compiled in as C strings made at build time
CLIOBJ  := $(CLISRC:%.c=$(BUILD)/%.o) $(BUILD)/gen/teach_page.o

TESTSRC := $(wildcard tests/test_*.c)
TESTBIN := $(TESTSRC:tests/%.c=$(BUILD)/tests/%)
REFSRC  := $(wildcard tests/ref/*.c)
REFOBJ  := $(REFSRC:%.c=$(BUILD)/%.o)

DEPS_STAMP := $(BUILD)/.deps-ok
# the compiler and its flags as last used in $(BUILD): every object and program depends on
# it, and it is rewritten only when they change (make OPT=-O1, CC=clang, ...), so a build
# tree never mixes objects made with different flags
FLAGS_STAMP := $(BUILD)/.flags
FLAGS_LINE   = $(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(LDFLAGS)

PKG_CFLAGS = $(shell pkg-config --cflags $(PKGS))
PKG_LIBS   = $(shell pkg-config --libs $(LINKPKGS))
TEST_CFLAGS = $(shell pkg-config --cflags $(TESTPKGS))
TEST_LIBS   = $(shell pkg-config --libs $(TESTPKGS)) $(TESTNOPCLIBS)

.PHONY: all run test asan bench docs fuzz deps clean install uninstall FORCE
FUZZ_SECONDS ?= 120
all: $(PROG)

$(DEPS_STAMP): tools/deps.sh
	@sh tools/deps.sh
	@mkdir -p $(BUILD) && touch $@

deps: $(DEPS_STAMP)

$(FLAGS_STAMP): FORCE
	@mkdir -p $(BUILD)
	@if [ "$$(cat $@ 2>/dev/null)" != '$(FLAGS_LINE)' ]; then printf '%s\n' '$(FLAGS_LINE)' > $@; fi

$(BUILD)/%.o: %.c $(FLAGS_STAMP) | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(PKG_CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/gen/teach_page.c: cli/teach_page.html tools/text2c.sh
	@mkdir -p $(dir $@)
	sh tools/text2c.sh cli/teach_page.html teach_page > $@.tmp && mv $@.tmp $@

$(BUILD)/gen/teach_page.o: $(BUILD)/gen/teach_page.c cli/teach_page.h $(FLAGS_STAMP)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -include cli/teach_page.h -c $< -o $@

$(LIB): $(LIBOBJ)
	@rm -f $@
	ar rcs $@ $^

$(PROG): $(CLIOBJ) $(LIB) $(FLAGS_STAMP)
	$(CC) $(CFLAGS) $(LDFLAGS) -o $@ $(CLIOBJ) $(LIB) $(PKG_LIBS) -lm

$(BUILD)/tests/%: tests/%.c $(wildcard tests/usbmock/*.c) $(wildcard tests/devices/*.c) $(REFOBJ) $(LIB) $(FLAGS_STAMP) | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(PKG_CFLAGS) $(TEST_CFLAGS) -o $@ $< $(REFOBJ) $(LIB) $(TEST_LIBS) $(PKG_LIBS) -lm

$(BUILD)/tests/ref/%.o: tests/ref/%.c $(FLAGS_STAMP) | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(PKG_CFLAGS) $(TEST_CFLAGS) -MMD -MP -c $< -o $@

run: $(PROG)
	./$(PROG) render scenes/street.s74 -o street.png --stats street.json
	@echo "wrote street.png (stats in street.json)"

test: $(PROG) $(TESTBIN)
	@TUBE74=./$(PROG) sh tests/run.sh $(BUILD)

asan:
	$(MAKE) BUILD=build-asan OPT="-O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" \
	        LDFLAGS="-fsanitize=address,undefined" PROG=build-asan/tube74 test

bench: $(PROG)
	@sh tools/bench.sh

# the README's and docs/'s figure tables rewritten from a run (tools/docs.sh; DOCS_HOST=0:
# only the deterministic ones, which make test checks)
docs: $(PROG)
	@sh tools/docs.sh

fuzz:
	@sh tools/fuzz.sh $(FUZZ_SECONDS)

install: $(PROG)
	sh tools/install.sh "$(DESTDIR)" "$(PREFIX)" "$(PROG)" tube74.1

uninstall:
	rm -f "$(DESTDIR)$(PREFIX)/bin/tube74" "$(DESTDIR)$(PREFIX)/share/man/man1/tube74.1"

clean:
	rm -rf build build-asan tube74 street.png street.json

-include $(LIBOBJ:.o=.d) $(CLIOBJ:.o=.d) $(REFOBJ:.o=.d)

# keep the reference objects between runs (they are intermediate to the test programs)
.SECONDARY: $(REFOBJ)

# the peer of make bench: OSMesa drawing the same scene (tools/refbench.c)
$(BUILD)/bench/refbench: tools/refbench.c $(REFOBJ) $(LIB) $(FLAGS_STAMP) | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(PKG_CFLAGS) $(TEST_CFLAGS) -o $@ $< $(REFOBJ) $(LIB) $(TEST_LIBS) $(PKG_LIBS) -lm

# the differential soak (tests/soak.c): new hard scenes against the exact reference until
# SOAK_SECONDS are up; failing scenes are saved as build/soak/fail-*.s74
SOAK_SECONDS ?= 60
.PHONY: soak
$(BUILD)/tests/soak: tests/soak.c $(REFOBJ) $(LIB) $(FLAGS_STAMP) | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $(PKG_CFLAGS) $(TEST_CFLAGS) -o $@ $< $(REFOBJ) $(LIB) $(TEST_LIBS) $(PKG_LIBS) -lm

soak: $(BUILD)/tests/soak
	$(BUILD)/tests/soak --seconds $(SOAK_SECONDS) --out $(BUILD)/soak
