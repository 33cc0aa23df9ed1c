from setuptools import find_packages, setup

package_name = 'dukw_model'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description='ROS-free physical models shared by the simulator and the estimator.',
    license='Apache-2.0',
    tests_require=['pytest'],
)
