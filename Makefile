# meshcorr — one plain Makefile. Sources are found by wildcard, so adding a
# file to a module folder needs no edit here.
#   make            build everything into build/
#   make test       unit tests + gradient checks + integration (tests/run-tests.sh)
#   make bench      benchmarks under tests/bench/ (print ratios, never fail on time)
#   make demo       install deps, build, run the demo job on Debian's CGAL meshes
#   make install    PREFIX=/usr/local DESTDIR= SYSCONFDIR= (install-lib install-python: the client part;
#                   install-doc: README and the specs into $(PREFIX)/share/doc/meshcorr)
#   make doc-params PROTOCOL.md's parameter table and meshcorr(1)'s list from
#                   protocol/proto_params.h
PREFIX  ?= /usr/local
DESTDIR ?=
BUILD   ?= build

CC      ?= cc
CXX     ?= c++
PKGS     = draco
WARN     = -Wall -Wextra -Werror
OPT     ?= -O2 -g
CPPFLAGS += -D_GNU_SOURCE -Iworkers -Iprotocol -Iclient-c -Idaemon -Itests -I$(BUILD)/gen
# The project's one version (the file VERSION): every program's --version,
# mc_version(), the Python package's metadata and meshcorr.pc; objects are
# rebuilt when it changes.
MC_VERSION := $(shell cat VERSION)
CPPFLAGS += -DMC_VERSION='"$(MC_VERSION)"'

# -fPIC everywhere so libmeshcorr.so can take engine objects from the same
# archives; Debian's gcc builds PIE by default, so with
# -fno-semantic-interposition the code is the same as before.
PIC      = -fPIC -fno-semantic-interposition
CFLAGS   += -std=c11 $(OPT) $(WARN) $(PIC) -fopenmp -pthread
CXXFLAGS += -std=c++17 $(OPT) $(WARN) $(PIC) -pthread $(shell pkg-config --cflags draco)
LDLIBS   += $(shell pkg-config --libs $(PKGS) gnutls libseccomp) -lembree3 -lOpenMeshTools -lOpenMeshCore -lcholmod -larpack -llapacke -llapack -lOpenCL -lm -lstdc++ -fopenmp -pthread

# The engine library: everything under workers/ except the worker main.
ENGINE_C   := $(filter-out workers/main/%,$(wildcard workers/*/*.c))
ENGINE_CXX := $(wildcard workers/*/*.cpp)
ENGINE_OBJ := $(ENGINE_C:%.c=$(BUILD)/obj/%.o) $(ENGINE_CXX:%.cpp=$(BUILD)/obj/%.o)
ENGINE_LIB := $(BUILD)/libmcengine.a

# The wire protocol codec (pure C, libc only): its own library.
PROTO_C   := $(wildcard protocol/*.c)
PROTO_OBJ := $(PROTO_C:%.c=$(BUILD)/obj/%.o)
PROTO_LIB := $(BUILD)/libmcproto.a

# libmeshcorr: the client library (client-c/*.c). Users link it with
# libmcengine.a (mesh reading and Draco encoding) and libmcproto.a.
CLIENT_C   := $(wildcard client-c/*.c)
CLIENT_OBJ := $(CLIENT_C:%.c=$(BUILD)/obj/%.o)
CLIENT_LIB := $(BUILD)/libmeshcorr.a
# The shared libmeshcorr.so.1: the client objects plus the engine and codec
# members they need (the linker takes only those from the archives); it
# exports mc_* only (client-c/meshcorr.map).
CLIENT_SO  := $(BUILD)/libmeshcorr.so.1
# libmeshcorr-engine.so.1: mc_match, a job run in the caller's process
# (client-c/local/) the way a worker runs it: the worker's job mapping, the
# engine and the codec linked in; exports mc_match and mc_match_stages
# only (client-c/local/meshcorr-engine.map). The Python
# package loads it for meshcorr.match(), so libmeshcorr.so stays slim.
LOCAL_C    := $(wildcard client-c/local/*.c)
LOCAL_OBJ  := $(LOCAL_C:%.c=$(BUILD)/obj/%.o) \
  $(addprefix $(BUILD)/obj/workers/main/,worker_job.o worker_result.o worker_progress.o)
ENGINE_SO  := $(BUILD)/libmeshcorr-engine.so.1

# meshcorrd: daemon/*.c; every file but main.c also goes into libmcdaemon.a
# so tests can drive a module (the scheduler) directly.
DAEMON_C    := $(wildcard daemon/*.c)
DAEMON_OBJ  := $(DAEMON_C:%.c=$(BUILD)/obj/%.o)
DAEMON_LIB  := $(BUILD)/libmcdaemon.a
DAEMON_LIBS := $(shell pkg-config --libs libuv) -lsqlite3 -lmodbus -lmicrohttpd -lsystemd

CLI_C   := $(wildcard client-c/cli/*.c)
CLI_OBJ := $(CLI_C:%.c=$(BUILD)/obj/%.o)

# The CLI's pictures (client-c/render/: rasteriser and PNG writer): linked
# into the CLI, the worker (--picture, for the web UI) and the tests only,
# so libmeshcorr.so never needs libpng.
RENDER_C    := $(wildcard client-c/render/*.c)
RENDER_OBJ  := $(RENDER_C:%.c=$(BUILD)/obj/%.o)
RENDER_LIB  := $(BUILD)/libmcrender.a
RENDER_CFLAGS := $(shell pkg-config --cflags libpng)
RENDER_LIBS := $(shell pkg-config --libs libpng)
$(RENDER_OBJ): CPPFLAGS += $(RENDER_CFLAGS)

TEST_SUPPORT_C   := $(wildcard tests/support/*.c)
TEST_SUPPORT_OBJ := $(TEST_SUPPORT_C:%.c=$(BUILD)/obj/%.o)
TEST_C    := $(wildcard tests/unit/test_*.c)
TEST_BIN  := $(TEST_C:tests/unit/%.c=$(BUILD)/tests/%)
# tests/security/: attacks on a real daemon, each one that must fail.
SEC_C     := $(wildcard tests/security/test_*.c)
SEC_BIN   := $(SEC_C:tests/security/%.c=$(BUILD)/tests/security/%)
BENCH_C   := $(wildcard tests/bench/bench_*.c)
BENCH_BIN := $(BENCH_C:tests/bench/%.c=$(BUILD)/bench/%)
FUZZ_C    := $(wildcard tests/fuzz/fuzz_*.c)
FUZZ_BIN  := $(FUZZ_C:tests/fuzz/%.c=$(BUILD)/fuzz/%)

# workers/main holds two programs: meshcorr-validate is worker_validate.c
# (its main) with the job's one mapping and the shared option code; the
# worker is the rest. The validator links --as-needed, so it loads Draco and
# none of the solvers' libraries (it starts once per SUBMIT).
VALIDATE_C   := workers/main/worker_validate.c workers/main/worker_job.c workers/main/worker_cli.c
VALIDATE_OBJ := $(VALIDATE_C:%.c=$(BUILD)/obj/%.o)
WORKER_C     := $(filter-out workers/main/worker_validate.c,$(wildcard workers/main/*.c))
WORKER_OBJ   := $(WORKER_C:%.c=$(BUILD)/obj/%.o)

PROGRAMS := $(BUILD)/meshcorr $(BUILD)/meshcorr-worker $(BUILD)/meshcorr-validate $(BUILD)/meshcorrd

.PHONY: all test bench demo install install-lib install-man install-python install-doc clean doc-params
# Objects built through pattern chains are kept (make would otherwise delete
# them after the run and print that as the last line of `make test`).
.SECONDARY:
all: $(PROGRAMS)

$(BUILD)/obj/%.o: %.c VERSION
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -MMD -MP -c $< -o $@

$(BUILD)/obj/%.o: %.cpp VERSION
	@mkdir -p $(dir $@)
	$(CXX) $(CPPFLAGS) $(CXXFLAGS) -MMD -MP -c $< -o $@

# The OpenCL program text, embedded as C arrays (ener_ocl.c includes them).
OCL_SRC := workers/ener/ener_normal.h workers/ener/ener_membrane.h workers/ener/ener_ocl_kernels.cl
$(BUILD)/gen/ener_ocl_src.h: $(OCL_SRC)
	@mkdir -p $(dir $@)
	set -e; for s in $(OCL_SRC); do echo "static const char ener__ocl_$$(basename $$s | tr . _)[] = {"; \
	  xxd -i < $$s; echo ", 0};"; done > $@.tmp; mv $@.tmp $@
$(BUILD)/obj/workers/ener/ener_ocl.o: $(BUILD)/gen/ener_ocl_src.h

# The web UI's pages, scripts and style sheet (daemon/web/), embedded as C
# arrays and a table of them by file name (web.c includes it): the daemon
# serves them from its binary.
WEB_ASSETS := $(sort $(wildcard daemon/web/*.html daemon/web/*.js daemon/web/*.css))
$(BUILD)/gen/web_assets.h: $(WEB_ASSETS)
	@mkdir -p $(dir $@)
	set -e; for s in $(WEB_ASSETS); do echo "static const unsigned char web__$$(basename $$s | tr .- __)[] = {"; \
	  xxd -i < $$s; echo "};"; done > $@.tmp; \
	echo "static const struct web_asset web__assets[] = {" >> $@.tmp; \
	for s in $(WEB_ASSETS); do n=$$(basename $$s); v=web__$$(echo $$n | tr .- __); \
	  echo "    {\"$$n\", $$v, sizeof $$v},"; done >> $@.tmp; \
	echo "};" >> $@.tmp; mv $@.tmp $@
$(BUILD)/obj/daemon/web.o: $(BUILD)/gen/web_assets.h

$(ENGINE_LIB): $(ENGINE_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(PROTO_LIB): $(PROTO_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(CLIENT_LIB): $(CLIENT_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(RENDER_LIB): $(RENDER_OBJ)
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(CLIENT_SO): $(CLIENT_OBJ) $(ENGINE_LIB) $(PROTO_LIB) client-c/meshcorr.map
	$(CC) $(CFLAGS) -shared -Wl,-soname,libmeshcorr.so.1 -Wl,--no-undefined \
	  -Wl,--version-script=client-c/meshcorr.map -o $@ $(CLIENT_OBJ) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS)
	ln -sf libmeshcorr.so.1 $(BUILD)/libmeshcorr.so

$(ENGINE_SO): $(LOCAL_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB) client-c/local/meshcorr-engine.map
	$(CC) $(CFLAGS) -shared -Wl,-soname,libmeshcorr-engine.so.1 -Wl,--no-undefined \
	  -Wl,--version-script=client-c/local/meshcorr-engine.map -o $@ $(LOCAL_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) \
	  $(PROTO_LIB) $(LDLIBS)
	ln -sf libmeshcorr-engine.so.1 $(BUILD)/libmeshcorr-engine.so


$(DAEMON_LIB): $(filter-out $(BUILD)/obj/daemon/main.o,$(DAEMON_OBJ))
	@mkdir -p $(dir $@)
	rm -f $@ && ar rcs $@ $^

$(BUILD)/meshcorr: $(CLI_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	$(CC) $(CFLAGS) -o $@ $(CLI_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS) $(RENDER_LIBS)

$(BUILD)/meshcorrd: $(BUILD)/obj/daemon/main.o $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	$(CC) $(CFLAGS) -o $@ $< $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(DAEMON_LIBS) $(LDLIBS)

$(BUILD)/meshcorr-worker: $(WORKER_OBJ) $(RENDER_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	$(CC) $(CFLAGS) -o $@ $(WORKER_OBJ) $(RENDER_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS) $(RENDER_LIBS)

$(BUILD)/meshcorr-validate: $(VALIDATE_OBJ) $(ENGINE_LIB) $(PROTO_LIB)
	$(CC) $(CFLAGS) -Wl,--as-needed -o $@ $(VALIDATE_OBJ) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS)

$(BUILD)/tests/%: tests/unit/%.c $(TEST_SUPPORT_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(RENDER_CFLAGS) -Itests $(CFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS) $(DAEMON_LIBS) $(RENDER_LIBS)

$(BUILD)/tests/security/%: tests/security/%.c $(TEST_SUPPORT_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(RENDER_LIB) $(CLIENT_LIB) $(DAEMON_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS) $(DAEMON_LIBS) $(RENDER_LIBS)

$(BUILD)/bench/%: tests/bench/%.c $(TEST_SUPPORT_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS)

$(BUILD)/fuzz/%: tests/fuzz/%.c $(TEST_SUPPORT_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(LDLIBS)

test: $(PROGRAMS) $(CLIENT_SO) $(ENGINE_SO) $(TEST_BIN) $(SEC_BIN) $(FUZZ_BIN)
	@sh tests/run-tests.sh $(TEST_BIN) $(SEC_BIN) $(FUZZ_BIN)

bench: $(PROGRAMS) $(BENCH_BIN)
	@for b in $(BENCH_BIN); do echo "== $$b"; ./$$b || exit 1; done

# The job parameter table of PROTOCOL.md, between its params:begin/end
# markers, from the one list (test_proto_params fails when it is stale).
doc-params: $(BUILD)/meshcorr
	$(BUILD)/meshcorr params --markdown > $(BUILD)/params.md
	awk -v t=$(BUILD)/params.md '/<!-- params:end/ { while ((getline l < t) > 0) print l; skip = 0 } \
	  !skip { print } /<!-- params:begin/ { skip = 1 }' protocol/PROTOCOL.md > $(BUILD)/PROTOCOL.md.tmp
	mv $(BUILD)/PROTOCOL.md.tmp protocol/PROTOCOL.md
	$(BUILD)/meshcorr params --mdoc > $(BUILD)/params.mdoc
	awk -v t=$(BUILD)/params.mdoc '/^\.\\" params:end/ { while ((getline l < t) > 0) print l; skip = 0 } \
	  !skip { print } /^\.\\" params:begin/ { skip = 1 }' deploy/man/meshcorr.1 > $(BUILD)/meshcorr.1.tmp
	mv $(BUILD)/meshcorr.1.tmp deploy/man/meshcorr.1

demo:
	sh deploy/install-deps.sh
	$(MAKE) all
	sh deploy/demo.sh $(BUILD)

# The daemon's config: /etc for PREFIX=/usr (a package), else $(PREFIX)/etc,
# so an install into a folder of one's own needs no root.
SYSCONFDIR ?= $(if $(filter /usr,$(PREFIX)),/etc,$(PREFIX)/etc)
install: $(PROGRAMS)
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/systemd/system $(DESTDIR)$(SYSCONFDIR)/meshcorr
	install -m 755 $(PROGRAMS) $(DESTDIR)$(PREFIX)/bin/
	sed -e 's|/usr/bin/meshcorrd|$(PREFIX)/bin/meshcorrd|' -e 's|/etc/meshcorr/|$(SYSCONFDIR)/meshcorr/|' \
	  -e 's|/usr/share/doc/meshcorr/|$(DOCDIR)/|g' \
	  deploy/meshcorrd.service > $(DESTDIR)$(PREFIX)/lib/systemd/system/meshcorrd.service
	chmod 644 $(DESTDIR)$(PREFIX)/lib/systemd/system/meshcorrd.service
	test -e $(DESTDIR)$(SYSCONFDIR)/meshcorr/meshcorrd.conf || \
	  install -m 644 deploy/meshcorrd.conf $(DESTDIR)$(SYSCONFDIR)/meshcorr/meshcorrd.conf
	test -e $(DESTDIR)$(SYSCONFDIR)/meshcorr/tokens || install -m 600 /dev/null $(DESTDIR)$(SYSCONFDIR)/meshcorr/tokens

# The man pages (deploy/man/NAME.SECTION), each into its section's folder.
MAN_PAGES := $(wildcard deploy/man/*.[1-8])
install: install-man
install-man:
	set -e; for p in $(MAN_PAGES); do d=$(DESTDIR)$(PREFIX)/share/man/man$${p##*.}; \
	  install -d $$d; install -m 644 $$p $$d/; done

# The documentation, where the unit's Documentation= points, in the
# repository's own layout so that the pages' links to each other work.
DOCDIR ?= $(PREFIX)/share/doc/meshcorr
DOCS   := README.md $(wildcard docs/*.md) protocol/PROTOCOL.md daemon/README.md daemon/MODBUS.md workers/WORKER.md
install: install-doc
install-doc:
	set -e; for f in $(DOCS); do d=$(DESTDIR)$(DOCDIR)/$$(dirname $$f); \
	  install -d $$d; install -m 644 $$f $$d/; done

# libmeshcorr: headers in include/meshcorr/ (meshcorr.h and the parameter
# list it includes; pkg-config's Cflags name the folder, so both
# <meshcorr.h> and <meshcorr/meshcorr.h> work), static and shared
# libraries, pkg-config file (the engine and codec archives too: static
# users link them, see Libs.private).
all: $(CLIENT_SO) $(ENGINE_SO)
install: install-lib
install-lib: $(CLIENT_LIB) $(CLIENT_SO) $(ENGINE_SO) $(ENGINE_LIB) $(PROTO_LIB)
	install -d $(DESTDIR)$(PREFIX)/include/meshcorr $(DESTDIR)$(PREFIX)/lib/pkgconfig
	install -m 644 client-c/meshcorr.h protocol/proto_params.h $(DESTDIR)$(PREFIX)/include/meshcorr/
	install -m 644 $(CLIENT_LIB) $(ENGINE_LIB) $(PROTO_LIB) $(DESTDIR)$(PREFIX)/lib/
	install -m 755 $(CLIENT_SO) $(ENGINE_SO) $(DESTDIR)$(PREFIX)/lib/
	ln -sf libmeshcorr.so.1 $(DESTDIR)$(PREFIX)/lib/libmeshcorr.so
	ln -sf libmeshcorr-engine.so.1 $(DESTDIR)$(PREFIX)/lib/libmeshcorr-engine.so
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@VERSION@|$(MC_VERSION)|' -e 's|@LIBS@|$(strip $(LDLIBS))|' \
	  client-c/meshcorr.pc.in > $(DESTDIR)$(PREFIX)/lib/pkgconfig/meshcorr.pc

# The Python package (client-c/python/meshcorr) where Debian's python3 finds
# it: /usr/lib/python3/dist-packages for PREFIX=/usr, else
# PREFIX/lib/python3.X/dist-packages (/usr/local's is on Debian's path);
# _libpath.py names the installed libmeshcorr.so.1 ($MESHCORR_LIB overrides).
PYTHON_SITE ?= $(if $(filter /usr,$(PREFIX)),$(PREFIX)/lib/python3/dist-packages,$(PREFIX)/lib/$(shell \
  /usr/bin/python3 -c 'import sys; print("python%d.%d" % sys.version_info[:2])' 2>/dev/null || echo python3)/dist-packages)
install: install-python
install-python: install-lib
	install -d $(DESTDIR)$(PYTHON_SITE)/meshcorr
	install -m 644 client-c/python/meshcorr/*.py client-c/python/meshcorr/py.typed $(DESTDIR)$(PYTHON_SITE)/meshcorr/
	printf '"""_libpath.py — written by make install: the installed libmeshcorr."""\nLIBMESHCORR = "%s"\n' \
	  '$(PREFIX)/lib/libmeshcorr.so.1' > $(DESTDIR)$(PYTHON_SITE)/meshcorr/_libpath.py

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
