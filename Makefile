# lubkit build.
#
#   make            build build/lib/liblub.a and every program into build/bin/
#   make test       unit tests of src/ and case tests of the programs; ends "N passed, N failed"
#   make demo       install missing packages, build, run the wedge tutorial, print its error
#   make bench      benchmarks (microseconds per particle-step, time to accuracy)
#   make install PREFIX=/usr/local    programs, library, headers, lubkit.pc, etc/, tutorials
#   make clean
#
# Sources are found by globbing: a file src/<concern>/<name>.c joins the library, a folder
# applications/<kind>/<program>/ becomes build/bin/<program>, a file tests/unit/<name>_test.c
# becomes the test program build/tests/<name>_test.  Nothing needs to be listed here.
#
# SANITIZE=address builds into build-asan/ with AddressSanitizer (make SANITIZE=address test).
# PETSC=0 builds without PETSc (the 'petsc' linear solver), PETSC=1 requires it; by default
# it is built in when installed (bin/installDeps installs it).  MPI=0 builds without MPI
# (lubFoam -parallel); by default MPI comes with PETSc.  HDF5=mpi links Open MPI's HDF5
# (lubFoam -parallel writes and reads its particle files collectively), HDF5=serial the
# serial one (a parallel run gathers its particles to rank 0 to write); by default mpi with
# MPI when libhdf5-openmpi-dev is installed.  The build says which (a line "lubkit: HDF5 ...").
#
# Code generation: OPT (default -O3) and ARCH (default -march=native: the processor building
# is the one running, as on a workstation or a cluster's compute node; `make ARCH=` builds
# binaries for any x86-64).  The wider vectors change no result: floating-point contraction
# (fused multiply-add) is off, and the solver's sums keep their order (the thesis wedge's
# particles after 96 steps are bit-identical between -O2 and -O3 -march=native), while a step
# costs 2-7% less on two threads, 2-15% on one (tutorials/README.md).  -fno-math-errno: no
# caller reads errno after sqrt, and without it a loop with sqrt does not vectorise (the
# neighbour lists' weights).  A change of CC, OPT or ARCH rebuilds everything.

CC       ?= cc
PREFIX   ?= /usr/local
OPT      ?= -O3
ARCH     ?= -march=native
BUILD    ?= build

ifeq ($(SANITIZE),address)
  BUILD  := build-asan
  OPT    := -O1 -fno-omit-frame-pointer -fsanitize=address,undefined
  LDSAN  := -fsanitize=address,undefined
endif

# Dependencies: pkg-config where the Debian package ships a .pc file (libyaml, HDF5);
# SuiteSparse 5 (Debian 12) ships none, so CHOLMOD is found by its header folder.
PKGS          := yaml-0.1
# PETSc (Debian petsc-dev, with Open MPI, hypre and MUMPS): the solver 'petsc' of
# system/solution.yaml (src/linalg/petsc_solver.h).  Built in when pkg-config finds PETSc and
# Open MPI's C binding (the Debian PETSc.pc does not name mpi.h's folder); PETSC=0 leaves it
# out, PETSC=1 requires it.  Only petsc_solver.c sees PETSc's and MPI's headers.
PETSC_ORIGIN  := $(origin PETSC)
PETSC         ?= $(if $(shell pkg-config --exists PETSc ompi-c 2>/dev/null && echo y),1,0)
ifeq ($(PETSC),1)
  PETSC_PC    := PETSc ompi-c
  PETSC_CFLAGS := -DLUB_HAVE_PETSC $(shell pkg-config --cflags $(PETSC_PC))
  PETSC_LIBS  := $(shell pkg-config --libs $(PETSC_PC))
  ifeq ($(PETSC_LIBS),)
    $(error PETSC=1 but pkg-config finds no PETSc and ompi-c: install petsc-dev (bin/installDeps))
  endif
endif
# MPI (Open MPI, with PETSc: `mpirun -np N lubFoam -parallel`, src/parallel/par.h): built in
# with PETSc, whose distributed solves a parallel run needs; MPI=0 leaves it out (lubFoam
# -parallel is then an error saying so).  Only src/parallel/par.c sees MPI's header.
MPI           ?= $(PETSC)
ifeq ($(MPI),1)
  ifneq ($(PETSC),1)
    $(error MPI=1 needs PETSc (PETSC=1) for the distributed pressure solve)
  endif
  MPI_CFLAGS  := -DLUB_HAVE_MPI $(shell pkg-config --cflags ompi-c)
endif
# HDF5 (doc/parallel.md, "One HDF5 for every program"): one library for all programs, chosen
# here.  With MPI, Open MPI's HDF5 (Debian libhdf5-openmpi-dev, pkg-config hdf5-openmpi) when
# installed: lubFoam -parallel then writes each particle file collectively (MPI-IO, every
# rank its rows) and a restart reads each rank's rows; the serial programs open their files
# with HDF5's default driver and never start MPI.  PETSc links that library already (every
# program of an MPI build loads libmpi and libhdf5_openmpi through it), so the serial HDF5
# would be a second copy.  Otherwise the serial HDF5 by its own name (Debian's `hdf5` is an
# alternative that points to the MPI build once libhdf5-openmpi-dev is installed), and a
# parallel run gathers its particles to rank 0, which writes.  Only particles_io.c uses it
# (it sees H5_HAVE_PARALLEL from hdf5.h).
HDF5          ?= $(if $(and $(filter 1,$(MPI)),$(shell pkg-config --exists hdf5-openmpi 2>/dev/null && echo y)),mpi,serial)
ifeq ($(HDF5),mpi)
  ifneq ($(MPI),1)
    $(error HDF5=mpi needs MPI (MPI=1, with PETSc))
  endif
  HDF5_PC     := hdf5-openmpi
  ifeq ($(shell pkg-config --exists hdf5-openmpi 2>/dev/null && echo y),)
    $(error HDF5=mpi but pkg-config finds no hdf5-openmpi: install libhdf5-openmpi-dev (bin/installDeps))
  endif
  HDF5_SAYS   := HDF5 of Open MPI (hdf5-openmpi): lubFoam -parallel writes and reads its particle files collectively
else ifeq ($(HDF5),serial)
  HDF5_PC     := $(if $(shell pkg-config --exists hdf5-serial 2>/dev/null && echo y),hdf5-serial,hdf5)
  HDF5_SAYS   := serial HDF5 ($(HDF5_PC)): lubFoam -parallel gathers its particles to rank 0 to write
else
  $(error HDF5=$(HDF5): expected mpi or serial)
endif
PKGS          += $(HDF5_PC)
PKG_CFLAGS    := $(shell pkg-config --cflags $(PKGS) 2>/dev/null)
PKG_LIBS      := $(shell pkg-config --libs $(PKGS) 2>/dev/null)
CHOLMOD_INC   ?= $(firstword $(wildcard /usr/include/suitesparse /usr/local/include/suitesparse))
CHOLMOD_LIBS  ?= -lcholmod -lsuitesparseconfig

VERSION  := $(shell cat VERSION 2>/dev/null || echo 0.0.0)
GITREV   := $(shell git rev-parse --short HEAD 2>/dev/null || echo unknown)

CPPFLAGS += -Isrc $(if $(CHOLMOD_INC),-I$(CHOLMOD_INC)) $(PKG_CFLAGS) \
            -D_POSIX_C_SOURCE=200809L -DLUB_VERSION='"$(VERSION)"' -DLUB_GITREV='"$(GITREV)"'
CFLAGS   += -std=c11 $(OPT) $(ARCH) -ffp-contract=off -fno-math-errno -g -Wall -Wextra -fopenmp -MMD -MP
LDLIBS   += $(PKG_LIBS) $(CHOLMOD_LIBS) $(PETSC_LIBS) -lm
LDFLAGS  += -fopenmp $(LDSAN)

LIB_SRC   := $(sort $(shell find src -name '*.c'))
LIB_OBJ   := $(LIB_SRC:%.c=$(BUILD)/obj/%.o)
LIB       := $(BUILD)/lib/liblub.a

APP_DIRS  := $(sort $(dir $(wildcard applications/*/*/*.c)))
PROGRAMS  := $(foreach d,$(APP_DIRS),$(notdir $(patsubst %/,%,$(d))))
BINS      := $(PROGRAMS:%=$(BUILD)/bin/%)

TEST_SRC  := $(sort $(wildcard tests/unit/*_test.c))
TEST_BINS := $(TEST_SRC:tests/unit/%.c=$(BUILD)/tests/%)

BENCH_SRC  := $(sort $(wildcard tests/bench/*_bench.c))
BENCH_BINS := $(BENCH_SRC:tests/bench/%.c=$(BUILD)/bench/%)

.PHONY: all test demo bench install clean deps format tests
.SECONDARY:
all: $(LIB) $(BINS)

# The code-generation flags of the objects in $(BUILD): rewritten (and so newer than every
# object) only when they change.
FLAGS_STAMP := $(BUILD)/flags
FLAGS_NOW   := $(CC) $(OPT) $(ARCH) -fno-math-errno PETSC=$(PETSC) MPI=$(MPI) HDF5=$(HDF5)
$(shell mkdir -p $(BUILD) && { [ "$$(cat $(FLAGS_STAMP) 2>/dev/null)" = '$(FLAGS_NOW)' ] \
          || echo '$(FLAGS_NOW)' > $(FLAGS_STAMP); })

$(BUILD)/obj/%.o: %.c $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CFLAGS) -c $< -o $@

$(BUILD)/obj/src/linalg/petsc_solver.o: CPPFLAGS += $(PETSC_CFLAGS)
$(BUILD)/obj/src/parallel/par.o: CPPFLAGS += $(MPI_CFLAGS)

$(LIB): $(LIB_OBJ)
	@mkdir -p $(dir $@)
	@echo 'lubkit: $(HDF5_SAYS)'
	@rm -f $@
	ar rcs $@ $^

# One program per folder: every .c in applications/<kind>/<program>/ is linked into it.
define program_rule
$(BUILD)/bin/$(1): $(patsubst %.c,$(BUILD)/obj/%.o,$(wildcard $(2)*.c)) $(LIB)
	@mkdir -p $$(dir $$@)
	$$(CC) $$(LDFLAGS) -o $$@ $$^ $$(LDLIBS)
endef
$(foreach d,$(APP_DIRS),$(eval $(call program_rule,$(notdir $(patsubst %/,%,$(d))),$(d))))

$(BUILD)/tests/%_test: $(BUILD)/obj/tests/unit/%_test.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

# The allocation counter of tests/cases/allocation (an LD_PRELOAD library; not in the
# AddressSanitizer build, whose runtime owns the allocator).
ALLOC_COUNT := $(if $(SANITIZE),,$(BUILD)/tests/liballoccount.so)
$(BUILD)/tests/liballoccount.so: tests/tools/alloccount.c $(FLAGS_STAMP)
	@mkdir -p $(dir $@)
	$(CC) -std=c11 -O2 -g -Wall -Wextra -fPIC -shared -o $@ $<

# A test tool linked with liblub (tests/cases/parallel builds a state particleGen does not make).
$(BUILD)/tests/particleMove: $(BUILD)/obj/tests/tools/particleMove.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

# tests/cases/dropBench checks drop_bench's pair sums (the neighbour lists against all pairs).
tests: all $(TEST_BINS) $(ALLOC_COUNT) $(BUILD)/tests/particleMove $(BUILD)/bench/drop_bench

$(BUILD)/bench/%_bench: $(BUILD)/obj/tests/bench/%_bench.o $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(LDFLAGS) -o $@ $^ $(LDLIBS)

# deps: install missing Debian packages only when pkg-config or the CHOLMOD header is missing
# (PETSc too, unless PETSC=0 was asked for, and mpirun with MPI).
PETSC_DEP := $(if $(and $(filter command environment,$(PETSC_ORIGIN)),$(filter 0,$(PETSC))),,PETSc ompi-c)
deps:
	@pkg-config --exists $(PKGS) $(PETSC_DEP) 2>/dev/null && [ -n "$(CHOLMOD_INC)" ] \
	  && command -v gnuplot >/dev/null && { [ "$(MPI)" != 1 ] || command -v mpirun >/dev/null; } \
	  || bin/installDeps

# The recursive make re-reads pkg-config after deps may have installed packages.
test: deps
	@$(MAKE) --no-print-directory tests
	@LUB_BUILD=$(BUILD) tests/run

demo: deps
	@$(MAKE) --no-print-directory all
	@LUB_BUILD=$(BUILD) bin/lubDemo

bench: deps
	@$(MAKE) --no-print-directory all $(BENCH_BINS)
	@LUB_BUILD=$(BUILD) tests/bench/run

# make install: a tree that works by itself (tests/cases/install runs a tutorial from one):
#   PREFIX/bin/                  the programs and the scripts of bin/
#   PREFIX/lib/liblub.a, PREFIX/lib/pkgconfig/lubkit.pc
#   PREFIX/include/lubkit/<concern>/*.h      (#include "io/dict.h", as in src/)
#   PREFIX/share/lubkit/         etc/ (bashrc, RunFunctions, templates), tutorials/, doc/,
#                                README.md: etc/bashrc there puts PREFIX/bin on PATH, and
#                                the tutorials' Allrun find it next to the programs on PATH
# The tutorials and doc/ are the files git tracks (no results of runs in the source tree),
# or the whole folders outside a git checkout.  DESTDIR stages the tree for a package.
SHARE := $(DESTDIR)$(PREFIX)/share/lubkit
.PHONY: $(BUILD)/lubkit.pc
$(BUILD)/lubkit.pc:
	@mkdir -p $(dir $@)
	@{ echo 'prefix=$(PREFIX)'; echo 'libdir=$${prefix}/lib'; \
	   echo 'includedir=$${prefix}/include'; echo; echo 'Name: lubkit'; \
	   echo 'Description: MPS thin-film lubrication toolkit: the core library liblub'; \
	   echo 'Version: $(VERSION)'; echo 'Requires: $(PKGS) $(PETSC_PC)'; \
	   echo 'Cflags: -I$${includedir}/lubkit $(if $(CHOLMOD_INC),-I$(CHOLMOD_INC)) -fopenmp'; \
	   echo 'Libs: -L$${libdir} -llub $(CHOLMOD_LIBS) -lm -fopenmp $(LDSAN)'; } >$@

install: all $(BUILD)/lubkit.pc
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(PREFIX)/lib/pkgconfig $(SHARE)
	install -m 755 $(BINS) $(DESTDIR)$(PREFIX)/bin/
	for f in bin/*; do install -m 755 $$f $(DESTDIR)$(PREFIX)/bin/; done
	install -m 644 $(LIB) $(DESTDIR)$(PREFIX)/lib/
	install -m 644 $(BUILD)/lubkit.pc $(DESTDIR)$(PREFIX)/lib/pkgconfig/
	cd src && for h in $$(find . -name '*.h'); do \
	    install -D -m 644 $$h $(DESTDIR)$(PREFIX)/include/lubkit/$$h || exit 1; done
	rm -rf $(SHARE)/etc $(SHARE)/tutorials $(SHARE)/doc
	cp -r etc $(SHARE)/
	install -m 644 README.md VERSION $(SHARE)/
	if git ls-files --error-unmatch tutorials/README.md >/dev/null 2>&1; then \
	    git ls-files tutorials doc | while IFS= read -r f; do \
	        if [ -x "$$f" ]; then m=755; else m=644; fi; \
	        install -D -m $$m "$$f" "$(SHARE)/$$f" || exit 1; done; \
	else cp -r tutorials doc $(SHARE)/; fi

format:
	clang-format -i $$(find src applications tests -name '*.[ch]')

clean:
	rm -rf build build-asan

-include $(shell find $(BUILD)/obj -name '*.d' 2>/dev/null)
