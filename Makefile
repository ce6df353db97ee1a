# Two entry points (see README): `make demo` and `make test`. Both install what is missing
# (the Debian packages of this release, 12 or 13), configure and build, then run.
SHELL := /bin/bash
BUILD_DIR ?= build
PLUGIN_DIR := $(BUILD_DIR)/lib/paraview-plugins/ReservoirMultiresolution
PLUGIN := $(PLUGIN_DIR)/ReservoirMultiresolution.so
DEMO_DECK ?= Testing/Data/demo_faulted_dome.grdecl
DEMO_OUTPUT ?= demo-output
# -noreset: by default Xvfb resets when its last client leaves, and a client connecting during
# the reset is refused ("bad X server connection"); tests connect one after another.
XVFB := xvfb-run -a -s '-screen 0 1280x1024x24 -noreset'
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

# The Debian release picks the package list: 12 (bookworm) has ParaView 5.11 built with Qt 5,
# 13 (trixie) ParaView 5.13 built with Qt 6; releases after 13 get 13's list.
DEBIAN_RELEASE ?= $(shell . /etc/os-release 2>/dev/null; \
  case "$$VERSION_ID:$$VERSION_CODENAME" in (12:*|*:bookworm) echo 12 ;; (*) echo 13 ;; esac)

# The ParaView SDK and the -dev packages its CMake config needs; build tools; the test oracle
# (OPM), a virtual display for headless rendering and xdotool to drive the GUI in its test.
PACKAGES := paraview paraview-dev python3-paraview python3-numpy xvfb xauth xdotool \
  cmake ninja-build g++ liblzo2-dev libglm-dev python3-opm-common
ifeq ($(DEBIAN_RELEASE),12)
PACKAGES += \
  qtbase5-dev libqt5svg5-dev qttools5-dev libqt5x11extras5-dev qtxmlpatterns5-dev-tools \
  libqt5opengl5-dev libutfcpp-dev libhdf5-dev libnetcdf-dev libgdal-dev libboost-dev \
  libopenmpi-dev openmpi-bin python3-mpi4py libtheora-dev libavcodec-dev libavformat-dev libavutil-dev \
  libswscale-dev libgl2ps-dev libglew-dev libxml2-dev liblz4-dev liblzma-dev libjpeg-dev \
  libpng-dev libtiff-dev libfreetype-dev libexpat1-dev zlib1g-dev libx11-dev libxt-dev \
  python3-dev libgl-dev libdouble-conversion-dev libjsoncpp-dev libpugixml-dev libfmt-dev \
  libcgns-dev libprotobuf-dev protobuf-compiler libogg-dev libsqlite3-dev libproj-dev \
  nlohmann-json3-dev
else
# What ParaView 5.13's and VTK 9.3's find-package lists ask for on Debian 13.
PACKAGES += \
  qt6-base-dev qt6-5compat-dev qt6-tools-dev qt6-svg-dev \
  libboost-dev libexpat1-dev libeigen3-dev libfreetype-dev libgl2ps-dev libglew-dev libhdf5-dev \
  libjpeg-dev liblz4-dev liblzma-dev libxml2-dev libopenmpi-dev openmpi-bin libnetcdf-dev \
  libgl-dev libopengl-dev libglx-dev libpng-dev libtiff-dev libtheora-dev libx11-dev libxt-dev \
  libxcursor-dev zlib1g-dev libdouble-conversion-dev python3-mpi4py libutfcpp-dev python3-dev
endif

.PHONY: all deps configure build demo test clean

all: build

# Idempotent: installs only packages that are not installed yet.
deps:
	@missing=$$(for p in $(PACKAGES); do dpkg-query -W -f='$${Status}' $$p 2>/dev/null \
	  | grep -q "install ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing: $$missing"; \
	  $(SUDO) apt-get update && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y --no-install-recommends $$missing; \
	else echo "All required Debian packages are installed."; fi

$(BUILD_DIR)/build.ninja:
	cmake -S . -B $(BUILD_DIR) -G Ninja -DBUILD_SHARED_LIBS=ON -DCMAKE_BUILD_TYPE=Release

configure: deps $(BUILD_DIR)/build.ninja

build: configure
	cmake --build $(BUILD_DIR)

# The main job: a generated faulted model of 3 million cells (with 3 report steps), its
# multiresolution hierarchy (.resmr + .resmrp), opened with the Multiresolution Surface
# representation: with a display, in the ParaView GUI to fly through; without one, the demo
# deck's screenshots and a scripted fly-through of the generated model in $(DEMO_OUTPUT)/.
DEMO_MODEL := $(DEMO_OUTPUT)/FAULTED
demo: build
	@mkdir -p $(DEMO_OUTPUT)
	@if [ ! -s $(DEMO_MODEL).resmrp ]; then \
	  echo "demo: generating a faulted 400x300x25 model and its hierarchy in $(DEMO_OUTPUT)/" && \
	  $(BUILD_DIR)/bin/resmr synth 400 300 25 --steps 3 --quiet -o $(DEMO_MODEL).EGRID >/dev/null && \
	  $(BUILD_DIR)/bin/resmr build $(DEMO_MODEL).EGRID -o $(DEMO_MODEL).resmr --quiet && \
	  $(BUILD_DIR)/bin/resmr add-properties $(DEMO_MODEL).resmr $(DEMO_MODEL).EGRID >/dev/null; \
	fi
	@if [ -n "$$DISPLAY" ]; then \
	  echo "Opening $(DEMO_MODEL).resmr in ParaView (plugin from $(PLUGIN_DIR))"; \
	  PV_PLUGIN_PATH=$(abspath $(PLUGIN_DIR)) RESMR_DEMO_FILE=$(abspath $(DEMO_MODEL).resmr) \
	    paraview --script=scripts/demo_view.py; \
	else \
	  $(XVFB) pvpython --force-offscreen-rendering scripts/demo.py $(PLUGIN) $(DEMO_DECK) $(DEMO_OUTPUT) && \
	  $(XVFB) pvpython --force-offscreen-rendering scripts/demo_view.py $(PLUGIN) $(DEMO_MODEL).resmr $(DEMO_OUTPUT); \
	fi

test: build
	cd $(BUILD_DIR) && $(XVFB) ctest --output-on-failure

clean:
	rm -rf $(BUILD_DIR) $(DEMO_OUTPUT)
